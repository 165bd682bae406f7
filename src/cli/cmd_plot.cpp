// `planarvo plot`: figures and a calibration report, drawn by the Python package planarvo.plot
// (matplotlib). This command only finds the interpreter, the package and the library, and hands
// its arguments over: execv(python3 -m planarvo.plot ARGS...).
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "common.h"

#ifndef PLANARVO_SOURCE_PYTHON_DIR
#define PLANARVO_SOURCE_PYTHON_DIR ""
#endif
#ifndef PLANARVO_PYTHON
#define PLANARVO_PYTHON "/usr/bin/python3"
#endif

namespace planarvo::cli {
namespace {

bool exists(const std::string& path) { return !path.empty() && access(path.c_str(), F_OK) == 0; }

std::string exe_dir() {
  std::vector<char> buf(4096);
  const ssize_t n = readlink("/proc/self/exe", buf.data(), buf.size() - 1);
  if (n <= 0) return ".";
  std::string path(buf.data(), static_cast<size_t>(n));
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

// The directory holding planarvo/plot: the installed one beside the tool, else the source tree's.
std::string package_dir(const std::string& bin) {
  const std::string installed = bin + "/../lib/python3/dist-packages";
  if (exists(installed + "/planarvo/plot/__main__.py")) return installed;
  const std::string source = PLANARVO_SOURCE_PYTHON_DIR;
  if (exists(source + "/planarvo/plot/__main__.py")) return source;
  return "";
}

void prepend_env(const char* name, const std::string& dir) {
  const char* old = std::getenv(name);
  const std::string value = old && *old ? dir + ":" + old : dir;
  setenv(name, value.c_str(), 1);
}

}  // namespace

int cmd_plot(int argc, char** argv) {
  const char* env_python = std::getenv("PLANARVO_PYTHON");
  const std::string python = env_python && *env_python ? env_python : PLANARVO_PYTHON;
  if (python.find('\'') != std::string::npos) throw UsageError("PLANARVO_PYTHON must not contain a quote");
  if (access(python.c_str(), X_OK) != 0)
    throw UsageError("the figures need Python 3 with matplotlib, and " + python +
                     " is not there: install python3-matplotlib (scripts/install-deps.sh does), or set "
                     "PLANARVO_PYTHON to a python3 that has it");
  const std::string bin = exe_dir();
  const std::string pkg = package_dir(bin);
  if (pkg.empty())
    throw UsageError("the Python package planarvo.plot is neither installed beside this program (" + bin +
                     "/../lib/python3/dist-packages) nor in the source tree it was built from");
  prepend_env("PYTHONPATH", pkg);
  // The library beside the tool in a build tree; an installed package finds its own.
  const char* library = std::getenv("PLANARVO_LIBRARY");
  if ((!library || !*library) && exists(bin + "/libplanarvo.so"))
    setenv("PLANARVO_LIBRARY", (bin + "/libplanarvo.so").c_str(), 1);
  // A missing matplotlib is reported by the package itself (exit 2), which saves importing it twice.
  std::vector<char*> args = {const_cast<char*>(python.c_str()), const_cast<char*>("-m"),
                             const_cast<char*>("planarvo.plot")};
  for (int i = 1; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  std::fflush(stdout);
  execv(python.c_str(), args.data());
  std::fprintf(stderr, "planarvo plot: cannot run %s: %s\n", python.c_str(), std::strerror(errno));
  return kExitFailed;
}

}  // namespace planarvo::cli
