// Helpers shared by the tests: scratch directories, paths to shared data, running the CLI.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include <gtest/gtest.h>

namespace planarvo::test {

inline std::filesystem::path shared_dir() { return PLANARVO_SHARED_DIR; }
inline std::filesystem::path source_dir() { return PLANARVO_SOURCE_DIR; }
inline std::filesystem::path texture(const std::string& name) {
  return shared_dir() / "data" / "textures" / name;
}

// A fresh, empty directory under the build tree, unique per test, removed on destruction.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "scratch";
    for (char& c : name)
      if (c == '/') c = '_';
    path_ = std::filesystem::path(PLANARVO_BINARY_DIR) / "test-scratch" / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    if (!std::getenv("PLANARVO_KEEP_SCRATCH")) {
      std::error_code ec;
      std::filesystem::remove_all(path_, ec);
    }
  }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& s) const { return path_ / s; }

 private:
  std::filesystem::path path_;
};

// The temporaries (core/output_file.h: PATH.partial-<random>) left beside path.
inline int partial_files(const std::filesystem::path& path) {
  int n = 0;
  const std::string prefix = path.filename().string() + ".partial";
  for (const auto& e : std::filesystem::directory_iterator(path.parent_path()))
    n += e.path().filename().string().rfind(prefix, 0) == 0 ? 1 : 0;
  return n;
}

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs a shell command line, stdout and stderr together.
inline CommandResult run_command(const std::string& command) {
  CommandResult r;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Runs the planarvo command-line tool with the given arguments (a shell-quoted string), and
// with env (shell-quoted NAME=value words, e.g. "POCL_CACHE_DIR=/tmp/x") added to its
// environment. env is passed to env(1), so "-u NAME" words, before any NAME=value, remove a
// variable (e.g. "-u HOME TMPDIR=/tmp/x").
inline CommandResult run_cli(const std::string& args, const std::string& env = "") {
  return run_command((env.empty() ? "" : "env " + env + " ") + "\"" + PLANARVO_CLI_PATH + "\" " + args);
}

// A whole file's bytes ("" when it cannot be read).
inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace planarvo::test
