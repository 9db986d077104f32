#include "core/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "core/error.h"
#include "core/temporary_name.h"

namespace mmh {

void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write) {
  const std::filesystem::path temporary = TemporaryBeside(path);
  try {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      ThrowBadValue(path.string(), "an unwritable path (" + std::string(std::strerror(errno)) + ")",
                    "a writable file in an existing folder");
    }
    write(out);
    out.flush();
    if (!out) ThrowBadValue(path.string(), "a failed write", "enough space to write the file");
    out.close();
    std::error_code ec;
    std::filesystem::rename(temporary, path, ec);
    if (ec)
      ThrowBadValue(path.string(), "a failed rename (" + ec.message() + ")", "a writable folder");
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << contents; });
}

void EnsureDirectory(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    ThrowBadValue(dir.string(), "a folder that cannot be created (" + ec.message() + ")",
                  "a writable output folder");
  }
}

}  // namespace mmh
