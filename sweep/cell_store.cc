#include "sweep/cell_store.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/text_parsing.h"

namespace mmh::sweep {
namespace {

namespace fs = std::filesystem;

std::string HostName() {
  char host[256] = {0};
  gethostname(host, sizeof(host) - 1);
  return host;
}

}  // namespace

fs::path CellDir(const fs::path& dir, const std::string& id) { return dir / "cells" / id; }

fs::path NewTempCellDir(const fs::path& dir, const std::string& id) {
  static std::atomic<int> counter{0};
  const fs::path temp = dir / "cells" /
                        ("." + id + ".tmp." + HostName() + "." + std::to_string(getpid()) + "." +
                         std::to_string(counter++));
  std::error_code ec;
  fs::remove_all(temp, ec);
  EnsureDirectory(temp);
  return temp;
}

CellStatus ReadCellStatus(const fs::path& dir, const std::string& id) {
  CellStatus status;
  const fs::path file = CellDir(dir, id) / "status.json";
  std::error_code ec;
  if (!fs::exists(file, ec)) return status;
  // Never published half (rename): a status.json that does not parse was not written by mmh, and
  // the cell counts as not run.
  nlohmann::json j;
  try {
    j = ReadJsonFile(file);
  } catch (const InputError&) {
    return status;
  }
  if (!j.is_object()) return status;
  status.exit_code = j.value("exit_code", -1);
  status.signal = j.value("signal", 0);
  status.stderr_tail = j.value("stderr_tail", std::string());
  status.state = status.exit_code == 0 && status.signal == 0 ? CellState::kComplete
                                                             : CellState::kFailed;
  return status;
}

std::string TailOfFile(const fs::path& file, int max_lines, std::size_t max_bytes) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "";
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  // Progress bars rewrite their line with '\r': keep what the line ended as.
  std::size_t start = text.size();
  int lines = 0;
  while (start > 0 && lines < max_lines && text.size() - start < max_bytes) {
    --start;
    if (text[start] == '\n') ++lines;
  }
  if (start < text.size() && text[start] == '\n') ++start;
  return text.substr(start);
}

void WriteStatus(const fs::path& temp, const CellStatus& status) {
  const nlohmann::json j = {{"exit_code", status.exit_code},
                            {"signal", status.signal},
                            {"stderr_tail", status.stderr_tail}};
  WriteFileAtomically(temp / "status.json", j.dump(2) + "\n");
}

bool PublishCell(const fs::path& dir, const std::string& id, const fs::path& temp) {
  const fs::path cell = CellDir(dir, id);
  std::error_code ec;
  if (fs::exists(cell, ec)) {
    if (ReadCellStatus(dir, id).state == CellState::kComplete) {
      fs::remove_all(temp, ec);
      return false;
    }
    // A failed cell: move it aside first (a rename onto a non-empty folder fails).
    const fs::path aside = fs::path(temp.string() + ".old");
    fs::rename(cell, aside, ec);
    fs::remove_all(aside, ec);
  }
  fs::rename(temp, cell, ec);
  if (ec) {
    // Another attempt published between our check and our rename: its result stands.
    fs::remove_all(temp, ec);
    return false;
  }
  return true;
}

std::vector<fs::path> TempCellDirs(const fs::path& dir, const std::string& id) {
  std::vector<fs::path> temps;
  std::error_code ec;
  const std::string prefix = "." + id + ".tmp.";
  for (fs::directory_iterator it(dir / "cells", ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().filename().string().rfind(prefix, 0) == 0) temps.push_back(it->path());
  }
  return temps;
}

void ClearCellForRerun(const fs::path& dir, const std::string& id) {
  std::error_code ec;
  for (const auto& temp : TempCellDirs(dir, id)) fs::remove_all(temp, ec);
  if (ReadCellStatus(dir, id).state == CellState::kComplete) return;
  const fs::path cell = CellDir(dir, id);
  if (!fs::exists(cell, ec)) return;
  const fs::path aside = dir / "cells" / ("." + id + ".rerun." + std::to_string(getpid()));
  fs::rename(cell, aside, ec);
  fs::remove_all(aside, ec);
}

}  // namespace mmh::sweep
