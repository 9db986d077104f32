// Plugins: parts of mmh that link a heavy third-party library, built as shared objects beside the
// libraries and loaded with dlopen when first used, so that a process pays for the library only if
// it needs it (docs/architecture.md, "Start-up").
#pragma once

#include <filesystem>

namespace mmh {

// The address of `symbol` in the plugin `library` (a path), loading it on the first call (it
// stays loaded). A missing or unloadable plugin, or a missing symbol, is a std::runtime_error
// naming the file and the loader's message: a broken build, not bad input.
void* PluginSymbol(const std::filesystem::path& library, const char* symbol);

}  // namespace mmh
