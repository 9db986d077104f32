#include "core/stale_temporaries.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <regex>
#include <string>
#include <system_error>
#include <vector>

namespace mmh {

namespace {

// The PID in a temporary's name, or -1 when `name` is not one (NAME.tmp.PID.N[.EXT]).
long TemporaryOwner(const std::string& name) {
  static const std::regex kPattern(R"(^.+\.tmp\.([0-9]{1,9})\.[0-9]+(\.[A-Za-z0-9]+)?$)");
  std::smatch match;
  if (!std::regex_match(name, match, kPattern)) return -1;
  return std::stol(match[1].str());
}

// kill(pid, 0) fails with ESRCH only when no such process exists (EPERM: it exists).
bool ProcessRunning(long pid) {
  return pid == ::getpid() || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

}  // namespace

int RemoveStaleTemporaries(const std::filesystem::path& dir, bool subfolders) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return 0;
  std::vector<std::filesystem::path> stale;
  auto consider = [&](const std::filesystem::directory_entry& entry) {
    if (!entry.is_regular_file(ec)) return;
    const long owner = TemporaryOwner(entry.path().filename().string());
    if (owner > 0 && !ProcessRunning(owner)) stale.push_back(entry.path());
  };
  if (subfolders) {
    for (std::filesystem::recursive_directory_iterator it(dir, ec), end; !ec && it != end;
         it.increment(ec)) {
      consider(*it);
    }
  } else {
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end;
         it.increment(ec)) {
      consider(*it);
    }
  }
  int removed = 0;
  for (const auto& file : stale) removed += std::filesystem::remove(file, ec) ? 1 : 0;
  return removed;
}

}  // namespace mmh
