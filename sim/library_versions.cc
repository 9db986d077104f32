#include "sim/library_versions.h"

#include <embree3/rtcore_config.h>

#include "sim/embree_config.h"

namespace mmh::sim {

nlohmann::json LibraryVersions() {
  const char* config = EmbreeDeviceConfig();
  return {{"embree", RTC_VERSION_STRING},
          {"embree_device", config != nullptr ? config : "Embree's choice of kernels"}};
}

}  // namespace mmh::sim
