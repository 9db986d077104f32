#include "sim/library_versions.h"

#include <embree3/rtcore_config.h>

namespace mmh::sim {

nlohmann::json LibraryVersions() { return {{"embree", RTC_VERSION_STRING}}; }

}  // namespace mmh::sim
