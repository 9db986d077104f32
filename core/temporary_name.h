// The name of the temporary a writer fills beside its target before renaming it over the target
// (core/atomic_file.h, the image writer), and the reverse: whose temporary a file name is
// (core/stale_temporaries.h). One format, so that what the writers leave is what the sweeper finds.
#pragma once

#include <filesystem>
#include <string>

namespace mmh {

// `path` + ".tmp.PID.N" (N counts this process's temporaries), or with `keep_extension` the stem
// + ".tmp.PID.N" + the extension (OpenImageIO picks an image's format by its extension).
std::filesystem::path TemporaryBeside(const std::filesystem::path& path,
                                      bool keep_extension = false);

// The PID in a file name TemporaryBeside makes (NAME.tmp.PID.N or NAME.tmp.PID.N.EXT), or -1 when
// `filename` is not one.
long TemporaryOwner(const std::string& filename);

}  // namespace mmh
