// Loading the vision module: libplanarvo_vision.so, in the folder that PLANARVO_MODULE_DIR names,
// else in a "planarvo" folder beside this library (lib/planarvo/ when installed), else beside
// this library (the build folder), else in the configured install folder. It is loaded RTLD_LOCAL, so that its copies of the C API's names do
// not replace this library's, and attached with this library's version, so that a module of
// another version is refused rather than half used.
#include "capi/host/vision_module.h"

#include <dlfcn.h>

#include <cstdlib>
#include <string>
#include <filesystem>
#include <system_error>

#include "capi/module/attach.h"
#include "capi/status.h"
#include "planarvo/planarvo.h"

namespace planarvo::capi::host {
namespace {

namespace fs = std::filesystem;

constexpr const char* kModuleName = "libplanarvo_vision.so";

struct Module {
  void* handle = nullptr;
  std::string error;  // why it could not be loaded
};

void record_error(const char* message) { fail(PLANARVO_ERROR_INTERNAL, message); }

std::string this_library_dir() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&record_error), &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code ec;
  const fs::path self = fs::canonical(info.dli_fname, ec);
  return ec ? fs::path(info.dli_fname).parent_path().string() : self.parent_path().string();
}

Module load() {
  Module m;
  std::string tried;
  std::string dirs[4];
  if (const char* env = std::getenv("PLANARVO_MODULE_DIR"); env != nullptr && *env != '\0') dirs[0] = env;
  if (const std::string self = this_library_dir(); !self.empty()) {
    dirs[1] = self + "/planarvo";
    dirs[2] = self;
  }
  dirs[3] = PLANARVO_MODULE_INSTALL_DIR;
  for (const std::string& dir : dirs) {
    if (dir.empty()) continue;
    const std::string path = dir + "/" + kModuleName;
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      tried += (tried.empty() ? "" : ", ") + path;
      continue;
    }
    m.handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (m.handle == nullptr) {
      const char* why = dlerror();
      m.error = "planarvo cannot load its vision module " + path + ": " + (why ? why : "unknown error");
      return m;
    }
    const auto attach = reinterpret_cast<decltype(&planarvo_vision_attach)>(dlsym(m.handle, "planarvo_vision_attach"));
    if (attach == nullptr || attach(PLANARVO_VERSION_NUMBER, &record_error) != 0) {
      dlclose(m.handle);
      m.handle = nullptr;
      m.error = "planarvo's vision module " + path + " is not of this library's version " +
                PLANARVO_VERSION_STRING + " (reinstall planarvo)";
    }
    return m;
  }
  m.error = std::string("planarvo's vision module (images, OpenCL devices, tracking) is not installed: ") +
            "no " + kModuleName + " at " + tried;
  return m;
}

}  // namespace

void* vision_symbol(const char* name) noexcept {
  try {
    static const Module module = load();
    if (module.handle == nullptr) {
      fail(PLANARVO_ERROR_INTERNAL, module.error);
      return nullptr;
    }
    void* symbol = dlsym(module.handle, name);
    if (symbol == nullptr)
      fail(PLANARVO_ERROR_INTERNAL, std::string("planarvo's vision module has no ") + name + " (reinstall planarvo)");
    return symbol;
  } catch (...) {
    fail(PLANARVO_ERROR_INTERNAL, "out of memory while loading planarvo's vision module");
    return nullptr;
  }
}

}  // namespace planarvo::capi::host
