#include "core/temporary_name.h"

#include <unistd.h>

#include <atomic>
#include <regex>

namespace mmh {

std::filesystem::path TemporaryBeside(const std::filesystem::path& path, bool keep_extension) {
  // Unique per process and call, so that concurrent writers never share a temporary.
  static std::atomic<unsigned> counter{0};
  const std::string tag = ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  if (!keep_extension) {
    std::filesystem::path temporary = path;
    temporary += tag;
    return temporary;
  }
  return path.parent_path() / (path.stem().string() + tag + path.extension().string());
}

long TemporaryOwner(const std::string& filename) {
  static const std::regex kPattern(R"(^.+\.tmp\.([0-9]{1,9})\.[0-9]+(\.[A-Za-z0-9]+)?$)");
  std::smatch match;
  if (!std::regex_match(filename, match, kPattern)) return -1;
  return std::stol(match[1].str());
}

}  // namespace mmh
