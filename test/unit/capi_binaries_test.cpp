// The two binaries behind the C API (src/capi/README.md, "Two binaries"): libplanarvo.so exports
// every function of planarvo.h, maps neither OpenCV nor OpenCL, writes the files it owns without
// loading the vision module, and its forwarded functions reach the module with their errors.
#include <dlfcn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "planarvo/planarvo.h"
#include "common/test_util.h"

namespace {

const std::string kLibrary = std::string(PLANARVO_BINARY_DIR) + "/libplanarvo.so";

// The names declared "PLANARVO_API ... planarvo_xxx(" in the public headers, planarvo.h and the
// parts it includes (plain string search: GCC 12 warns inside std::regex under AddressSanitizer).
std::set<std::string> header_functions() {
  std::stringstream text;
  for (const char* header : {"planarvo.h", "dataset.h", "calibration.h", "mosaic.h"}) {
    std::ifstream in(planarvo::test::source_dir() / "include" / "planarvo" / header);
    text << in.rdbuf();
  }
  const std::string h = text.str();
  std::set<std::string> names;
  for (size_t at = h.find("PLANARVO_API "); at != std::string::npos; at = h.find("PLANARVO_API ", at + 1)) {
    const size_t paren = h.find('(', at);
    const size_t name = h.rfind("planarvo_", paren);
    if (paren == std::string::npos || name == std::string::npos || name < at) continue;
    names.insert(h.substr(name, paren - name));
  }
  return names;
}

struct Library {
  Library() : handle(dlopen(kLibrary.c_str(), RTLD_NOW | RTLD_LOCAL)) {}
  ~Library() {
    if (handle) dlclose(handle);
  }
  template <class F>
  F get(const char* name) const {
    return reinterpret_cast<F>(dlsym(handle, name));
  }
  void* handle;
};

TEST(CApiBinaries, TheLibraryExportsEveryFunctionOfTheHeader) {
  const Library lib;
  ASSERT_NE(lib.handle, nullptr) << dlerror();
  const std::set<std::string> names = header_functions();
  EXPECT_GE(names.size(), 50u);  // the parse found the header's functions
  for (const std::string& name : names) EXPECT_NE(dlsym(lib.handle, name.c_str()), nullptr) << name;
}

TEST(CApiBinaries, TheLibraryMapsNeitherOpenCVNorOpenCL) {
  std::unique_ptr<FILE, int (*)(FILE*)> ldd(popen(("ldd " + kLibrary).c_str(), "r"), pclose);
  ASSERT_TRUE(ldd);
  std::string deps;
  char line[512];
  while (std::fgets(line, sizeof line, ldd.get())) deps += line;
  EXPECT_NE(deps.find("libcholmod"), std::string::npos) << deps;  // ldd did list the dependencies
  EXPECT_EQ(deps.find("libopencv"), std::string::npos) << deps;
  EXPECT_EQ(deps.find("libOpenCL"), std::string::npos) << deps;
}

bool module_mapped() {
  std::ifstream maps("/proc/self/maps");
  const std::string text((std::istreambuf_iterator<char>(maps)), std::istreambuf_iterator<char>());
  return text.find("libplanarvo_vision") != std::string::npos;
}

// Runs one test of this binary (a DISABLED_ one) alone in a new process, which has not loaded the
// module yet whatever the tests before it here did; its exit status.
int run_alone(const char* test) {
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string filter = std::string("--gtest_filter=") + test;
    execl("/proc/self/exe", "/proc/self/exe", filter.c_str(), "--gtest_also_run_disabled_tests",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(CApiBinaries, WritingFilesLoadsNoModule) {
  EXPECT_EQ(run_alone("CApiBinaries.DISABLED_WritingFilesLoadsNoModuleAlone"), 0);
}

// Run by WritingFilesLoadsNoModule in a process of its own.
TEST(CApiBinaries, DISABLED_WritingFilesLoadsNoModuleAlone) {
  ASSERT_FALSE(module_mapped());
  const Library lib;
  ASSERT_NE(lib.handle, nullptr) << dlerror();
  const auto last_error = lib.get<decltype(&planarvo_last_error)>("planarvo_last_error");
  const auto extrinsics_save = lib.get<decltype(&planarvo_extrinsics_save)>("planarvo_extrinsics_save");
  const auto camera_save = lib.get<decltype(&planarvo_camera_save)>("planarvo_camera_save");
  const auto write_tum = lib.get<decltype(&planarvo_write_tum)>("planarvo_write_tum");
  const auto write_plane = lib.get<decltype(&planarvo_write_plane)>("planarvo_write_plane");
  const auto camera_load = lib.get<decltype(&planarvo_camera_load)>("planarvo_camera_load");
  ASSERT_TRUE(last_error && extrinsics_save && camera_save && write_tum && write_plane && camera_load);

  const std::string dir = PLANARVO_BINARY_DIR "/test-scratch";
  std::filesystem::create_directories(dir);
  const planarvo_extrinsics e = {0.2, -0.02, 0.18, 0.2, 0.3, -0.1};
  const double covariance[36] = {1e-6};
  ASSERT_EQ(extrinsics_save((dir + "/no_module_extrinsics.yaml").c_str(), &e, covariance, "x,yaw", "test", "notes"),
            PLANARVO_OK)
      << last_error();
  planarvo_camera camera = {};
  camera.width = 640;
  camera.height = 480;
  camera.fx = camera.fy = 500;
  camera.cx = 320;
  camera.cy = 240;
  ASSERT_EQ(camera_save((dir + "/no_module_camera.yaml").c_str(), &camera), PLANARVO_OK) << last_error();
  const double t[2] = {0.0, 0.1};
  const planarvo_se2 poses[2] = {{0, 0, 0}, {0.1, 0, 0.01}};
  ASSERT_EQ(write_tum((dir + "/no_module.tum").c_str(), t, poses, 2), PLANARVO_OK) << last_error();
  const planarvo_plane_attitude rows[1] = {{0.0, 0.01, -0.02, 0.001, 0.001}};
  ASSERT_EQ(write_plane((dir + "/no_module_plane.txt").c_str(), rows, 1), PLANARVO_OK) << last_error();
  EXPECT_FALSE(module_mapped());

  // The check sees the module once a call needs it: reading YAML does (cv::FileStorage).
  ASSERT_EQ(camera_load((dir + "/no_module_camera.yaml").c_str(), &camera), PLANARVO_OK) << last_error();
  EXPECT_TRUE(module_mapped());
  EXPECT_EQ(camera.fx, 500.0);
}

TEST(CApiBinaries, ForwardedFunctionsReachTheModuleWithTheirErrors) {
  const Library lib;
  ASSERT_NE(lib.handle, nullptr) << dlerror();
  const auto camera_load = lib.get<decltype(&planarvo_camera_load)>("planarvo_camera_load");
  const auto last_error = lib.get<decltype(&planarvo_last_error)>("planarvo_last_error");
  const auto sim_default_camera = lib.get<decltype(&planarvo_sim_default_camera)>("planarvo_sim_default_camera");
  ASSERT_TRUE(camera_load && last_error && sim_default_camera);

  // A value computed in the module comes back unchanged: the simulator's default camera, as
  // this test's own copy of the engine computes it.
  planarvo_camera camera, expected;
  ASSERT_EQ(sim_default_camera(640, 480, 75.0, &camera), PLANARVO_OK) << last_error();
  ASSERT_EQ(planarvo_sim_default_camera(640, 480, 75.0, &expected), PLANARVO_OK);
  EXPECT_EQ(std::memcmp(&camera, &expected, sizeof camera), 0);
  EXPECT_EQ(camera.width, 640);

  // An error raised in the module is the library's last error, on this thread.
  const std::string missing = PLANARVO_BINARY_DIR "/no-such-camera.yaml";
  EXPECT_NE(camera_load(missing.c_str(), &camera), PLANARVO_OK);
  EXPECT_NE(std::string(last_error()).find(missing), std::string::npos) << last_error();
}

}  // namespace
