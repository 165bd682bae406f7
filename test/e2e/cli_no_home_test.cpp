// The tool run as a service user with no home: HOME, XDG_CACHE_HOME, POCL_CACHE_DIR and
// PLANARVO_CACHE_DIR unset, or HOME a path nobody can write. PoCL 3.1 then cannot create its
// kernel cache (with HOME unset it takes /tmp/pocl, which the first user to run it owns) and
// finds no device; the engine gives PoCL, and its own program cache, a private directory under
// the temp directory, which these tests point at a scratch directory with TMPDIR.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/test_util.h"
#include "planarvo/planarvo.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::run_cli;
using test::ScratchDir;

// run_cli's environment words go to env(1), so -u removes a variable.
const std::string kNoHome = "-u HOME -u XDG_CACHE_HOME -u POCL_CACHE_DIR -u PLANARVO_CACHE_DIR ";

std::string in_temp(const fs::path& tmp) { return "TMPDIR=\"" + tmp.string() + "\""; }

fs::path private_dir(const fs::path& tmp) {
  return tmp / ("planarvo-" + std::to_string(::geteuid()));
}

void expect_only_owner_can_enter(const fs::path& dir) {
  struct stat st {};
  ASSERT_EQ(::lstat(dir.c_str(), &st), 0) << dir;
  EXPECT_TRUE(S_ISDIR(st.st_mode)) << dir;
  EXPECT_EQ(st.st_mode & 0777, 0700u) << dir;
}

// Whether the first device's driver keeps compiled kernels itself (PoCL; then the engine keeps
// no program cache unless told where).
bool driver_caches_kernels() {
  planarvo_device_info d{};
  d.struct_size = sizeof d;
  size_t n = 1;
  return planarvo_list_devices(&d, 1, &n) == PLANARVO_OK && n >= 1 && d.driver_caches_kernels != 0;
}

bool has_file_with_extension(const fs::path& dir, const std::string& ext) {
  if (!fs::is_directory(dir)) return false;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ext) return true;
  return false;
}

TEST(CliNoHome, DevicesListsADevice) {
  ScratchDir d;
  fs::create_directories(d / "tmp");
  auto r = run_cli("devices", kNoHome + in_temp(d / "tmp"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.rfind("0  ", 0), 0u) << r.output;  // the first line is device 0
  // PoCL was pointed at the private directory, which only this user can enter.
  expect_only_owner_can_enter(private_dir(d / "tmp"));
  EXPECT_TRUE(fs::is_directory(private_dir(d / "tmp") / "pocl")) << r.output;
}

// A HOME that exists on paper only, as for Debian's nobody (/nonexistent); a regular file here,
// so that not even root can create a cache under it.
TEST(CliNoHome, DevicesWithAHomeThatCannotBeWritten) {
  ScratchDir d;
  fs::create_directories(d / "tmp");
  std::ofstream(d / "home") << "not a directory\n";
  auto r = run_cli("devices", "-u XDG_CACHE_HOME -u POCL_CACHE_DIR -u PLANARVO_CACHE_DIR HOME=\"" +
                                  (d / "home").string() + "\" " + in_temp(d / "tmp"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.rfind("0  ", 0), 0u) << r.output;
  EXPECT_TRUE(fs::is_directory(private_dir(d / "tmp") / "pocl")) << r.output;
}

TEST(CliNoHome, SimulateAndTrack) {
  ScratchDir d;
  fs::create_directories(d / "tmp");
  // POCL_KERNEL_CACHE=0: PoCL keeps no kernel cache of its own, so the engine needs its program cache.
  const std::string env = kNoHome + "POCL_KERNEL_CACHE=0 " + in_temp(d / "tmp");
  auto r = run_cli("simulate --quiet --out \"" + (d / "seq").string() +
                       "\" --seconds 0.5 --width 160 --height 120",
                   env);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path trajectory = d / "trajectory.txt";
  r = run_cli("track --quiet \"" + (d / "seq").string() + "\" --extrinsics \"" +
                  (d / "seq" / "extrinsics_gt.yaml").string() + "\" -o \"" + trajectory.string() + "\"",
              env);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(trajectory)) << r.output;
  EXPECT_GT(fs::file_size(trajectory), 0u);
  // The program cache found a home too, so the tool had nothing to say about it.
  EXPECT_TRUE(has_file_with_extension(private_dir(d / "tmp") / "programs", ".clbin")) << r.output;
  EXPECT_EQ(r.output.find("note:"), std::string::npos) << r.output;

  // With PoCL's own cache on, the engine keeps none (the driver's serves later runs) and says nothing.
  fs::create_directories(d / "tmp2");
  r = run_cli("track --quiet \"" + (d / "seq").string() + "\" --extrinsics \"" +
                  (d / "seq" / "extrinsics_gt.yaml").string() + "\"",
              kNoHome + in_temp(d / "tmp2"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(fs::exists(private_dir(d / "tmp2") / "programs"), !driver_caches_kernels()) << r.output;
  EXPECT_EQ(r.output.find("note:"), std::string::npos) << r.output;
}

// No home and no usable temp directory: the program cache is off and the tool says so on one
// line; a POCL_CACHE_DIR of the user's own is used as it is.
TEST(CliNoHome, NoPlaceForTheCacheIsANote) {
  ScratchDir d;
  std::ofstream(d / "tmp") << "not a directory\n";
  // POCL_KERNEL_CACHE=0: a driver without a kernel cache of its own, for which the engine's matters.
  const std::string env = "-u HOME -u XDG_CACHE_HOME -u PLANARVO_CACHE_DIR POCL_KERNEL_CACHE=0 POCL_CACHE_DIR=\"" +
                          (d / "pocl").string() + "\" " + in_temp(d / "tmp");
  const std::string simulate = "simulate --quiet --seconds 0.2 --width 96 --height 64 --out ";
  auto r = run_cli(simulate + "\"" + (d / "seq").string() + "\"", env);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string note = "planarvo: note: no writable directory for the kernel program cache";
  const size_t at = r.output.find(note);
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_EQ(r.output.find(note, at + 1), std::string::npos) << r.output;  // once
  EXPECT_TRUE(fs::is_directory(d / "pocl")) << r.output;
  r = run_cli(simulate + "\"" + (d / "seq2").string() + "\" --no-cache", env);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("note:"), std::string::npos) << r.output;
}

// Nowhere for PoCL either (a HOME and a TMPDIR that are files): PoCL finds no device, and both
// messages say what to set.
TEST(CliNoHome, NoPlaceForPoclSaysToSetPoclCacheDir) {
  ScratchDir d;
  std::ofstream(d / "file") << "not a directory\n";
  const std::string env = "-u XDG_CACHE_HOME -u POCL_CACHE_DIR -u PLANARVO_CACHE_DIR HOME=\"" +
                          (d / "file").string() + "\" " + in_temp(d / "file");
  auto r = run_cli("devices", env);
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("POCL_CACHE_DIR"), std::string::npos) << r.output;
  r = run_cli("simulate --quiet --seconds 0.2 --width 96 --height 64 --out \"" + (d / "seq").string() + "\"",
              env);
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("set POCL_CACHE_DIR to a writable directory"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(d / "seq"));
}

}  // namespace
}  // namespace planarvo
