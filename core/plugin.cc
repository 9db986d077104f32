#include "core/plugin.h"

#include <dlfcn.h>

#include <mutex>
#include <stdexcept>
#include <string>

namespace mmh {

void* PluginSymbol(const std::filesystem::path& library, const char* symbol) {
  // dlopen keeps a reference count and its own lock; the mutex only keeps dlerror's message with
  // the call that failed.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  // RTLD_LOCAL: the plugin's libraries never interpose on the program's symbols.
  void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* message = dlerror();
    throw std::runtime_error("cannot load the plugin " + library.string() + " (" +
                             (message ? message : "unknown error") +
                             "); it is built with mmh: rebuild (./mmh build)");
  }
  dlerror();
  void* address = dlsym(handle, symbol);
  if (address == nullptr) {
    const char* message = dlerror();
    throw std::runtime_error("the plugin " + library.string() + " has no " + symbol + " (" +
                             (message ? message : "null symbol") + ")");
  }
  return address;
}

}  // namespace mmh
