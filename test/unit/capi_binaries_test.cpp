// The two binaries behind the C API (src/capi/README.md, "Two binaries"): libplanarvo.so exports
// every function of planarvo.h, maps neither OpenCV nor OpenCL, and its forwarded functions
// reach the vision module with their errors.
#include <dlfcn.h>

#include <cstdio>
#include <cstring>
#include <fstream>
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
  for (const char* header : {"planarvo.h", "dataset.h", "mosaic.h"}) {
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
