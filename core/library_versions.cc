#include "core/library_versions.h"

#include <OpenImageIO/oiioversion.h>

namespace mmh {

nlohmann::json LibraryVersions() { return {{"openimageio", OIIO_VERSION_STRING}}; }

}  // namespace mmh
