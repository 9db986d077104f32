#include "track/library_versions.h"

#include <pcl/pcl_config.h>

#include <opencv2/core/version.hpp>

namespace mmh::track {

nlohmann::json LibraryVersions() { return {{"pcl", PCL_VERSION_PRETTY}, {"opencv", CV_VERSION}}; }

}  // namespace mmh::track
