// Default cache locations for the program cache and for PoCL (see cache_dirs.h).
#include "ocl/cache_dirs.h"

#include <cerrno>
#include <cstdlib>
#include <string>
#include <system_error>

#include <sys/stat.h>
#include <unistd.h>

namespace planarvo::ocl::detail {
namespace fs = std::filesystem;
namespace {

// Where PoCL 3.1 puts its cache when POCL_CACHE_DIR is not set (lib/CL/pocl_cache.c): under
// $XDG_CACHE_HOME when it is not empty, else under $HOME, used as it is (even empty). Empty
// when HOME is unset: PoCL then uses /tmp/pocl, one directory for every user of the machine,
// which is not usable for the reason cache_dirs.h gives.
fs::path pocl_default_cache_dir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return fs::path(xdg) / "pocl" / "kcache";
  if (const char* home = std::getenv("HOME")) return fs::path(std::string(home) + "/.cache/pocl/kcache");
  return {};
}

}  // namespace

bool cache_dir_usable(const fs::path& dir) {
  if (dir.empty()) return false;
  fs::path p = dir;
  for (;;) {
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0)
      return S_ISDIR(st.st_mode) && ::access(p.c_str(), W_OK | X_OK) == 0;
    // ENOTDIR (a file on the way) or EACCES (a directory we cannot search): it cannot be made.
    if (errno != ENOENT) return false;
    fs::path parent = p.parent_path();
    if (parent.empty()) parent = ".";
    if (parent == p) return false;
    p = parent;
  }
}

fs::path user_cache_dir(const std::string& app) {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / app;
  if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / app;
  return {};
}

fs::path private_temp_dir() {
  std::error_code ec;
  const fs::path temp = fs::temp_directory_path(ec);
  if (ec || temp.empty()) return {};
  const uid_t uid = ::geteuid();
  const fs::path dir = temp / ("planarvo-" + std::to_string(uid));
  if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) return {};
  struct stat st {};
  if (::lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != uid ||
      (st.st_mode & (S_IWGRP | S_IWOTH)) != 0 || ::access(dir.c_str(), W_OK | X_OK) != 0)
    return {};
  return dir;
}

bool driver_caches_kernels(const std::string& platform_name) {
  if (platform_name != "Portable Computing Language") return false;
  const char* off = std::getenv("POCL_KERNEL_CACHE");
  return !(off && std::string(off) == "0");
}

const std::string& prepare_driver_environment() {
  // A function-local static: initialised once, and thread-safely, on the first device query.
  static const std::string problem = []() -> std::string {
    if (std::getenv("POCL_CACHE_DIR")) return {};  // the user's own choice, usable or not
    if (cache_dir_usable(pocl_default_cache_dir())) return {};
    const fs::path temp = private_temp_dir();
    if (temp.empty())
      return "If the driver is PoCL: it finds no device when it cannot create its cache "
             "directory, and neither $XDG_CACHE_HOME, $HOME nor the temp directory can hold "
             "one; set POCL_CACHE_DIR to a writable directory.";
    ::setenv("POCL_CACHE_DIR", (temp / "pocl").c_str(), 0);
    return {};
  }();
  return problem;
}

}  // namespace planarvo::ocl::detail
