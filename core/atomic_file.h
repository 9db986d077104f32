// Writing results without ever leaving a half-written file: write to a temporary name in the same
// folder, flush, then rename over the target (rename is atomic on POSIX file systems).
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace mmh {

// Calls `write` with a stream to a temporary file beside `path`, then renames it to `path`.
// Throws InputError naming the path if the folder is not writable; the temporary is removed on any
// failure, so `path` either keeps its old content or gets the complete new one.
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);

// Convenience for a string payload.
void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents);

// Creates `dir` (and parents) or throws InputError naming it.
void EnsureDirectory(const std::filesystem::path& dir);

}  // namespace mmh
