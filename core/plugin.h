// Plugins: parts of mmh that link a heavy third-party library, built as shared objects beside the
// libraries and loaded with dlopen when first used, so that a process pays for the library only if
// it needs it (docs/architecture.md, "Start-up").
//
// A plugin is found relative to the running executable, never by a path compiled in: in the build
// tree every program sits one folder below the build root (build/cli/mmh, build/tests/core_tests,
// build/bench/..., build/tools/...) and the plugins in build/lib/mmh/; an installed tree
// (`cmake --install`) has PREFIX/bin/mmh and PREFIX/lib/mmh/. So a moved or installed tree works,
// and a stale build tree at the old place is never loaded instead.
#pragma once

#include <filesystem>
#include <string>

namespace mmh {

// The environment variable that overrides the plugins' folder (for programs of a library user that
// do not sit in such a tree).
inline constexpr const char* kPluginDirVariable = "MMH_PLUGIN_DIR";

// The folder the plugins are loaded from: $MMH_PLUGIN_DIR when set and not empty, else
// ../lib/mmh from the folder of the running executable (/proc/self/exe, symbolic links resolved,
// like the loader's $ORIGIN). lib/mmh is the CMake variable MMH_PLUGIN_DIR, the plugins' folder
// under the build root and under the install prefix (CMakeLists.txt).
std::filesystem::path PluginDirectory();

// The address of `symbol` in the plugin file `file_name` of PluginDirectory(), loading it on the
// first call (it stays loaded). A missing or unloadable plugin, or a missing symbol, is a
// std::runtime_error naming the file, how its folder was found and the loader's message: a broken
// build or install, not bad input.
void* PluginSymbol(const std::string& file_name, const char* symbol);

}  // namespace mmh
