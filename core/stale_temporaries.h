// The temporaries a killed writer leaves behind (core/atomic_file.h writes through them).
#pragma once

#include <filesystem>

namespace mmh {

// Removes, in `dir` (and its subfolders with `subfolders`), the temporaries of writers that were
// killed: files named as core/temporary_name.h's TemporaryBeside names them whose PID is not a
// running process. A writer killed between its write and its rename leaves one, and a command
// that continues in place (`mmh run --resume`) would otherwise carry it for ever. Only for folders that one host writes: a PID is not unique across hosts, so a folder
// that cluster nodes write into (a sweep's cells/) must not be swept. Returns the number removed;
// a file that cannot be removed is left (it is never a result).
int RemoveStaleTemporaries(const std::filesystem::path& dir, bool subfolders = true);

}  // namespace mmh
