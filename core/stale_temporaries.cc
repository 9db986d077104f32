#include "core/stale_temporaries.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>
#include <vector>

#include "core/temporary_name.h"

namespace mmh {

namespace {

// kill(pid, 0) fails with ESRCH only when no such process exists (EPERM: it exists).
bool ProcessRunning(long pid) {
  return pid == ::getpid() || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

}  // namespace

int RemoveStaleTemporaries(const std::filesystem::path& dir, bool subfolders) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return 0;
  std::vector<std::filesystem::path> stale;
  for (std::filesystem::recursive_directory_iterator it(dir, ec), end; !ec && it != end;
       it.increment(ec)) {
    if (!subfolders) it.disable_recursion_pending();
    std::error_code entry_ec;  // an entry gone meanwhile is skipped, not the end of the listing
    if (!it->is_regular_file(entry_ec)) continue;
    const long owner = TemporaryOwner(it->path().filename().string());
    if (owner > 0 && !ProcessRunning(owner)) stale.push_back(it->path());
  }
  int removed = 0;
  for (const auto& file : stale) removed += std::filesystem::remove(file, ec) ? 1 : 0;
  return removed;
}

}  // namespace mmh
