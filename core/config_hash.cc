#include "core/config_hash.h"

#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace mmh {

std::string ConfigHash(const nlohmann::json& resolved_config) {
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a offset basis
  for (unsigned char c : resolved_config.dump()) {
    hash ^= c;
    hash *= 1099511628211ull;  // FNV prime
  }
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace mmh
