#include "core/staged_folder.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <system_error>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/text_parsing.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;

// Whether `target` may be replaced: absent, an empty folder, or a folder this writer wrote.
void RequireReplaceable(const fs::path& target) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(target, ec);
  if (!fs::exists(status)) return;
  const std::string expected = "a new or empty folder, or one written by mmh (it is replaced)";
  if (!fs::is_directory(status)) ThrowBadValue(target.string(), "an existing file", expected);
  if (fs::is_empty(target, ec)) return;
  bool ours = false;
  for (const char* marker : kMmhMarkerFiles) {
    const fs::path file = target / marker;
    if (ours || !fs::is_regular_file(file, ec)) continue;
    try {
      const nlohmann::json json =
          ParseJsonText(ReadTextFile(file, kMaxJsonFileBytes), file.string());
      ours = json.is_object() && json.value("writer", "") == kMmhWriterName;
    } catch (const InputError&) {
      ours = false;
    }
  }
  if (!ours) {
    ThrowBadValue(target.string(),
                  "an existing folder that mmh did not write (no camera.json, fakenect.json or "
                  "run.json with \"writer\": \"mmh\")",
                  expected);
  }
}

// Staging folders of live writers in this process: two writers must never share one.
std::mutex& ActiveStagingMutex() {
  static std::mutex mutex;
  return mutex;
}
std::set<fs::path>& ActiveStaging() {
  static std::set<fs::path> active;
  return active;
}

// Removes the staging folders ('<target>.partial-<pid>') and set-aside folders ('.old-<pid>') of
// `target` left by processes that no longer run (a SIGKILLed render): otherwise each killed run
// leaves up to tens of MB for ever. Folders of live processes (a concurrent writer) are kept.
// Process ids are those of this machine: writers of one folder on several hosts are not supported.
void RemoveStaleStaging(const fs::path& target) {
  const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const std::string name = target.filename().string();
  std::error_code ec;
  fs::directory_iterator it(parent, ec);
  if (ec) return;
  for (const fs::directory_entry& entry : it) {
    const std::string entry_name = entry.path().filename().string();
    for (const std::string suffix : {".partial-", ".old-"}) {
      if (!entry_name.starts_with(name + suffix)) continue;
      const std::string digits = entry_name.substr(name.size() + suffix.size());
      if (digits.empty() || digits.size() > 9 ||
          !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        continue;
      }
      const pid_t pid = static_cast<pid_t>(std::stol(digits));
      if (pid == ::getpid()) continue;                      // ours: handled by the caller
      if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to judge)
      std::error_code ignored;
      // A kill between Commit()'s two renames leaves the old folder aside and no target: put it
      // back (the rerun replaces it whole).
      if (suffix == ".old-" && !fs::exists(fs::symlink_status(target, ignored))) {
        fs::rename(entry.path(), target, ignored);
        if (!ignored) continue;
      }
      fs::remove_all(entry.path(), ignored);
    }
  }
}

}  // namespace

fs::path WithoutTrailingSeparator(const fs::path& path) {
  fs::path normal = path.lexically_normal();
  if (normal.has_filename()) return normal;
  return normal.parent_path();
}

StagedFolder::StagedFolder(const fs::path& target) : target_(WithoutTrailingSeparator(target)) {
  RequireReplaceable(target_);
  const fs::path parent = target_.parent_path().empty() ? fs::path(".") : target_.parent_path();
  std::error_code parent_error;
  fs::create_directories(parent, parent_error);
  if (!fs::is_directory(parent)) {
    ThrowBadValue(target_.string(),
                  "a parent folder that cannot be created (" + parent_error.message() + ")",
                  "a writable output folder");
  }
  RemoveStaleStaging(target_);
  staging_ = target_;
  staging_ += ".partial-" + std::to_string(::getpid());
  {
    std::lock_guard<std::mutex> lock(ActiveStagingMutex());
    if (!ActiveStaging().insert(staging_).second) {
      ThrowBadValue(target_.string(), "a folder another writer of this process is writing",
                    "one writer per output folder");
    }
  }
  try {
    // A leftover of a crashed run that had the same process id.
    std::error_code ec;
    fs::remove_all(staging_, ec);
    EnsureDirectory(staging_);
  } catch (...) {
    std::lock_guard<std::mutex> lock(ActiveStagingMutex());
    ActiveStaging().erase(staging_);
    throw;
  }
}

StagedFolder::~StagedFolder() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove_all(staging_, ignored);
  }
  std::lock_guard<std::mutex> lock(ActiveStagingMutex());
  ActiveStaging().erase(staging_);
}

void StagedFolder::Commit() {
  if (committed_) ThrowBadValue(target_.string(), "a second commit", "one commit per folder");
  // An old folder of ours is set aside first (rename cannot replace a non-empty folder), and put
  // back if the final rename fails.
  RequireReplaceable(target_);
  std::error_code ec;
  fs::path old;
  if (fs::exists(fs::symlink_status(target_, ec))) {
    old = target_;
    old += ".old-" + std::to_string(::getpid());
    fs::remove_all(old, ec);
    fs::rename(target_, old, ec);
    if (ec) {
      ThrowBadValue(target_.string(), "a folder that cannot be moved aside (" + ec.message() + ")",
                    "a writable output folder");
    }
  }
  fs::rename(staging_, target_, ec);
  if (ec) {
    std::error_code ignored;
    if (!old.empty()) fs::rename(old, target_, ignored);
    ThrowBadValue(target_.string(),
                  "a failed rename from " + staging_.string() + " (" + ec.message() + ")",
                  "a writable output folder");
  }
  if (!old.empty()) fs::remove_all(old, ec);
  committed_ = true;
}

}  // namespace mmh
