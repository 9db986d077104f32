#include "core/plugin.h"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <string>

namespace mmh {
namespace {

// From the executable's folder (bin/ or a folder of the build root) to the plugins' (CMake's
// MMH_PLUGIN_DIR under the prefix or the build root).
constexpr const char* kPluginDirFromExecutable = "../" MMH_PLUGIN_DIR;

// Where PluginDirectory() came from, for the error message.
std::string PluginDirectoryOrigin() {
  const char* variable = std::getenv(kPluginDirVariable);
  if (variable != nullptr && *variable != '\0') return std::string("$") + kPluginDirVariable;
  return std::string(kPluginDirFromExecutable) + " from the executable's folder";
}

}  // namespace

std::filesystem::path PluginDirectory() {
  const char* variable = std::getenv(kPluginDirVariable);
  if (variable != nullptr && *variable != '\0') return variable;
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) {
    throw std::runtime_error("cannot find the plugins: /proc/self/exe is unreadable (" +
                             ec.message() + "); set " + kPluginDirVariable +
                             " to the folder of libmmh_*.so");
  }
  return (self.parent_path() / kPluginDirFromExecutable).lexically_normal();
}

void* PluginSymbol(const std::string& file_name, const char* symbol) {
  const std::filesystem::path library = PluginDirectory() / file_name;
  // dlopen keeps a reference count and its own lock; the mutex only keeps dlerror's message with
  // the call that failed.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  // RTLD_LOCAL: the plugin's libraries never interpose on the program's symbols.
  void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* message = dlerror();
    throw std::runtime_error("cannot load the plugin " + library.string() + " (" +
                             (message ? message : "unknown error") + "; its folder is " +
                             PluginDirectoryOrigin() +
                             "); it is built with mmh (./mmh build) and installed with it");
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
