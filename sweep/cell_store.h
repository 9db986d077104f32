// The folders of a sweep's cells: DIR/cells/<id>/ holds the command's output (out/), its exit
// status and the tail of its errors (status.json), and where and how long it ran
// (provenance.json, the only file that differs between backends). A cell folder is written under
// a temporary name beside it and renamed when complete, so it is complete or absent.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mmh::sweep {

enum class CellState { kMissing, kComplete, kFailed };

struct CellStatus {
  CellState state = CellState::kMissing;
  int exit_code = 0;  // the command's exit code (0 ok, 1 failure, 2 bad input); -1 killed
  int signal = 0;     // the signal that ended the worker, or 0
  std::string stderr_tail;
};

std::filesystem::path CellDir(const std::filesystem::path& dir, const std::string& id);

// A fresh temporary folder for the cell, unique to this host and process:
// DIR/cells/.<id>.tmp.<host>.<pid>.
std::filesystem::path NewTempCellDir(const std::filesystem::path& dir, const std::string& id);

CellStatus ReadCellStatus(const std::filesystem::path& dir, const std::string& id);

// The last `max_lines` lines (at most `max_bytes`) of a text file ("" when absent).
std::string TailOfFile(const std::filesystem::path& file, int max_lines = 20,
                       std::size_t max_bytes = 4000);

// Writes status.json into the temporary folder.
void WriteStatus(const std::filesystem::path& temp, const CellStatus& status);

// Renames the temporary folder to the cell's folder. When a complete cell is already there (a
// duplicate run of a requeued task), it stays and the temporary is removed; a failed one is
// replaced. Returns whether this temporary became the cell.
bool PublishCell(const std::filesystem::path& dir, const std::string& id,
                 const std::filesystem::path& temp);

// Removes a failed cell's folder (to run it again) and the temporaries earlier attempts of this
// cell left (killed workers). Never touches a complete cell.
void ClearCellForRerun(const std::filesystem::path& dir, const std::string& id);

// The temporaries of `id` that exist now (an attempt that was killed, or one in progress).
std::vector<std::filesystem::path> TempCellDirs(const std::filesystem::path& dir,
                                                const std::string& id);

}  // namespace mmh::sweep
