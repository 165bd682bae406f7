// The FPGA/DSP path through the tool: kernels exported once (`planarvo kernels --export`), then
// `track` and `calibrate` run from them with --kernel-binaries, which never compiles (no program
// cache, an empty PoCL cache), give the numbers that kernels compiled at run time give; a
// variant missing from the manifest is exit 2, says which command needs it and how to export
// it, and leaves the output path unwritten; `--for track` exports a subset that suffices for
// track and not for calibrate.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>
#include <opencv2/core.hpp>

#include "common/test_util.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::run_cli;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// The numbers of a TUM trajectory, row by row (comments left out).
std::vector<std::vector<double>> read_tum(const fs::path& p) {
  std::vector<std::vector<double>> rows;
  for (const std::string& line : lines_of(read_text(p))) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    std::vector<double> row;
    for (double v; in >> v;) row.push_back(v);
    EXPECT_TRUE(in.eof()) << p << ": not a number in \"" << line << "\"";
    rows.push_back(row);
  }
  return rows;
}

// The six extrinsics and the 6x6 covariance of an extrinsics YAML, in that order (42 numbers).
std::vector<double> read_extrinsics(const fs::path& p) {
  cv::FileStorage fs(p.string(), cv::FileStorage::READ);
  EXPECT_TRUE(fs.isOpened()) << p;
  std::vector<double> out;
  for (const char* k : {"x", "y", "z", "roll", "pitch", "yaw"}) {
    EXPECT_TRUE(fs[k].isReal()) << p << ": " << k;
    out.push_back(static_cast<double>(fs[k]));
  }
  cv::Mat cov;
  fs["covariance"] >> cov;
  EXPECT_EQ(cov.rows, 6) << p;
  EXPECT_EQ(cov.cols, 6) << p;
  for (int i = 0; i < cov.rows; ++i)
    for (int j = 0; j < cov.cols; ++j) out.push_back(cov.at<double>(i, j));
  return out;
}

// A copy of a binaries directory whose manifest lacks the lines for one program variant.
void copy_without(const fs::path& from, const fs::path& to, const std::string& program,
                  const std::string& options) {
  fs::create_directories(to);
  for (const auto& e : fs::directory_iterator(from))
    if (e.path().filename() != "planarvo-kernels.txt") fs::copy_file(e.path(), to / e.path().filename());
  std::string kept;
  int dropped = 0;
  for (const std::string& line : lines_of(read_text(from / "planarvo-kernels.txt"))) {
    std::vector<std::string> f;
    std::istringstream in(line);
    for (std::string field; std::getline(in, field, '\t');) f.push_back(field);
    if (!line.empty() && line[0] != '#' && f.size() >= 6 && f[0] == program && f[5] == options) {
      ++dropped;
      continue;
    }
    kept += line + "\n";
  }
  ASSERT_EQ(dropped, 1) << "no manifest line for " << program << " with \"" << options << "\"";
  std::ofstream(to / "planarvo-kernels.txt", std::ios::binary) << kept;
}

// The tracker's STATS pass and the roll/pitch estimator's plain pass, as their default options
// build them (src/track/warp_reduce.cpp); the manifest spells them this way.
const char* const kTrackerStats = "-D NPARAM=3 -D WG_X=16 -D WG_Y=1 -D PIX=8 -D LANES=8 -D STATS=1 -D HIST_BINS=16";
const char* const kRollPitchPass = "-D NPARAM=5 -D WG_X=16 -D WG_Y=1 -D PIX=8 -D LANES=8";

// One simulated data set (320x240, 2 s) and one export of every kernel for the whole suite.
// Programs are compiled at run time into a program cache of the suite's own, which the export
// and the reference runs use; the runs from binaries use no program cache and an empty PoCL
// cache.
class KernelBinaries : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One directory per process: CTest runs each test in a process of its own, in parallel.
    root_ = new fs::path(fs::path(PLANARVO_BINARY_DIR) / "test-scratch" /
                         ("KernelBinaries-" + std::to_string(getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    auto r = run_cli("simulate --quiet --out " + sim() + " --seconds 2 --width 320 --height 240 " + compiled());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_cli("kernels --export " + all() + " " + compiled());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() {
    if (!std::getenv("PLANARVO_KEEP_SCRATCH")) {
      std::error_code ec;
      fs::remove_all(*root_, ec);
    }
    delete root_;
    root_ = nullptr;
  }
  void SetUp() override {
    ASSERT_TRUE(fs::is_regular_file(fs::path(all()) / "planarvo-kernels.txt")) << "the suite's set-up failed";
  }

  static std::string path(const std::string& name) { return (*root_ / name).string(); }
  static std::string sim() { return path("sim"); }
  static std::string all() { return path("all-kernels"); }
  static std::string compiled() { return "--cache-dir " + path("program-cache"); }
  static std::string track_args(const std::string& out) {
    return "track " + sim() + " --quiet --extrinsics " + sim() + "/extrinsics_gt.yaml -o " + out;
  }
  static std::string calibrate_args(const std::string& out) { return "calibrate " + sim() + " --quiet -o " + out; }
  // The no-compile mode, with a PoCL cache of its own that starts empty.
  static std::string from_binaries(const std::string& dir) { return " --no-cache --kernel-binaries " + dir; }
  static std::string empty_pocl_cache(const std::string& name) {
    const std::string d = path("pocl-cache-" + name);
    fs::create_directories(d);
    EXPECT_TRUE(fs::is_empty(d));
    return "POCL_CACHE_DIR=" + d;
  }

  static fs::path* root_;
};
fs::path* KernelBinaries::root_ = nullptr;

TEST_F(KernelBinaries, TrackAndCalibrateWithoutCompilingMatchRunTimeCompiledKernels) {
  auto r = run_cli(track_args(path("track-compiled.txt")) + " " + compiled());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli(track_args(path("track-binaries.txt")) + from_binaries(all()), empty_pocl_cache("track"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto compiled_traj = read_tum(path("track-compiled.txt"));
  const auto binaries_traj = read_tum(path("track-binaries.txt"));
  ASSERT_EQ(compiled_traj.size(), 60u);  // 2 s at 30 fps
  ASSERT_EQ(binaries_traj.size(), compiled_traj.size());
  for (size_t i = 0; i < compiled_traj.size(); ++i) {
    ASSERT_EQ(compiled_traj[i].size(), 8u) << "row " << i;
    ASSERT_EQ(binaries_traj[i].size(), 8u) << "row " << i;
    for (size_t k = 0; k < 8; ++k) EXPECT_NEAR(binaries_traj[i][k], compiled_traj[i][k], 1e-12) << "row " << i;
  }
  // Not a trivially equal pair: the robot moved.
  EXPECT_GT(std::hypot(compiled_traj.back()[1], compiled_traj.back()[2]), 0.1);

  r = run_cli(calibrate_args(path("calib-compiled.yaml")) + " " + compiled());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli(calibrate_args(path("calib-binaries.yaml")) + from_binaries(all()), empty_pocl_cache("calibrate"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto compiled_calib = read_extrinsics(path("calib-compiled.yaml"));
  const auto binaries_calib = read_extrinsics(path("calib-binaries.yaml"));
  ASSERT_EQ(compiled_calib.size(), 42u);
  ASSERT_EQ(binaries_calib.size(), 42u);
  for (size_t k = 0; k < 42; ++k)
    EXPECT_NEAR(binaries_calib[k], compiled_calib[k], 1e-12 * std::max(1.0, std::abs(compiled_calib[k]))) << k;
  EXPECT_GT(compiled_calib[2], 0.1);       // a camera height, not zeros
  EXPECT_GT(compiled_calib[6 + 0], 0.0);   // var(x): estimated
}

TEST_F(KernelBinaries, MissingManifestEntryIsExit2AndWritesNothing) {
  const std::string dir = path("without-tracker-stats");
  copy_without(all(), dir, "warp_reduce", kTrackerStats);
  const std::string out = path("track-missing.txt");
  const auto r = run_cli(track_args(out) + from_binaries(dir), empty_pocl_cache("missing"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // The program, its options, the directory, which command needs it and how to export it.
  EXPECT_NE(r.output.find("\"warp_reduce\" with options \"" + std::string(kTrackerStats) + "\""), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find(dir), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("never compiles"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("track"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("`planarvo kernels --export " + dir + " --for calibrate,track`"), std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("::"), std::string::npos) << r.output;  // no C++ names
}

// Every binary of a copy of the export truncated, rotated (each under the next one's name),
// corrupted by one byte, or replaced by a directory; and the manifest a directory. Each is exit
// 2 naming the file before the driver sees the bytes (issue 27: a truncated binary crashed the
// driver with SIGSEGV; one variant's binary under every variant's name ran and lost every frame;
// a directory was "internal error"), and the trajectory is not written.
TEST_F(KernelBinaries, DamagedBinariesAreExit2NamingTheFileBeforeTheDriverSeesThem) {
  std::vector<std::string> bins;
  for (const auto& e : fs::directory_iterator(all()))
    if (e.path().extension() == ".bin") bins.push_back(e.path().filename().string());
  std::sort(bins.begin(), bins.end());
  ASSERT_GE(bins.size(), 2u);
  const auto damaged = [&](const std::string& name, const std::function<void(const fs::path&)>& damage,
                           const std::string& says) {
    SCOPED_TRACE(name);
    const fs::path dir = path("damaged-" + name);
    fs::create_directories(dir);
    for (const auto& e : fs::directory_iterator(all())) fs::copy_file(e.path(), dir / e.path().filename());
    damage(dir);
    const std::string out = path("track-" + name + ".txt");
    const auto r = run_cli(track_args(out) + from_binaries(dir.string()), empty_pocl_cache(name));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_NE(r.output.find(dir.string()), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(says), std::string::npos) << r.output;
  };
  damaged("truncated", [&](const fs::path& d) {
    for (const std::string& b : bins) fs::resize_file(d / b, fs::file_size(d / b) / 2);
  }, "the manifest says");
  damaged("rotated", [&](const fs::path& d) {
    fs::rename(d / bins[0], d / "first");
    for (size_t i = 0; i + 1 < bins.size(); ++i) fs::rename(d / bins[i + 1], d / bins[i]);
    fs::rename(d / "first", d / bins.back());
  }, "manifest");
  damaged("corrupted", [&](const fs::path& d) {
    for (const std::string& b : bins) {
      std::fstream f(d / b, std::ios::in | std::ios::out | std::ios::binary);
      f.seekg(static_cast<std::streamoff>(fs::file_size(d / b) / 2));
      const char c = static_cast<char>(f.get());
      f.seekp(static_cast<std::streamoff>(fs::file_size(d / b) / 2));
      f.put(static_cast<char>(c ^ 0x5a));
    }
  }, "SHA-256");
  damaged("directories", [&](const fs::path& d) {
    for (const std::string& b : bins) {
      fs::remove(d / b);
      fs::create_directory(d / b);
    }
  }, "is not a file");
  damaged("manifest-directory", [&](const fs::path& d) {
    fs::remove(d / "planarvo-kernels.txt");
    fs::create_directory(d / "planarvo-kernels.txt");
  }, "is not a file");
}

TEST_F(KernelBinaries, ExportForTrackIsASubsetThatSufficesForTrack) {
  const std::string dir = path("track-kernels");
  auto r = run_cli("kernels --export " + dir + " --for track " + compiled());
  ASSERT_EQ(r.exit_code, 0) << r.output;

  // Every line of the subset is a line of the full export (same program, options and for
  // field), and the full export has more (the roll/pitch estimator's passes, the renderer).
  const auto entries = [](const std::string& d) {
    std::vector<std::string> out;
    for (const std::string& line : lines_of(read_text(fs::path(d) / "planarvo-kernels.txt"))) {
      if (line.empty() || line[0] == '#') continue;
      std::vector<std::string> f;
      std::istringstream in(line);
      for (std::string field; std::getline(in, field, '\t');) f.push_back(field);
      EXPECT_EQ(f.size(), 9u) << line;  // ... for, size, sha256
      f.resize(7);
      out.push_back(f[0] + " | " + f[5] + " | " + f[6]);
    }
    return out;
  };
  const auto subset = entries(dir), everything = entries(all());
  // undistort, pyramid, the tracker's plain and STATS passes, the same over a subsampled level
  // and the subsampling itself, the search for a motion where no guess is good enough, the
  // residual image's pass and the reduction of the honest-status check's texture residual, and the
  // local plane's seven-parameter passes (plain and STATS, whole and subsampled levels)
  EXPECT_EQ(subset.size(), 14u);
  for (const std::string& e : subset) {
    EXPECT_NE(std::find(everything.begin(), everything.end(), e), everything.end()) << e;
    EXPECT_NE(e.find("track"), std::string::npos) << e;
  }
  EXPECT_GT(everything.size(), subset.size());

  r = run_cli(track_args(path("track-subset.txt")) + from_binaries(dir), empty_pocl_cache("subset"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_tum(path("track-subset.txt")).size(), 60u);

  // calibrate needs the roll/pitch estimator's passes too: exit 2, naming it, nothing written.
  const std::string out = path("calib-subset.yaml");
  r = run_cli(calibrate_args(out) + from_binaries(dir), empty_pocl_cache("subset-calibrate"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_NE(r.output.find("\"warp_reduce\" with options \"" + std::string(kRollPitchPass) + "\""), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("The command calibrate uses it"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--for calibrate`"), std::string::npos) << r.output;
}

// What `--for calibrate` exports is all that calibrate runs (its tracking stage subsamples
// levels 0 and 1 as the tracker does by default: those passes were once exported for track only).
TEST_F(KernelBinaries, ExportForCalibrateSufficesForCalibrate) {
  const std::string dir = path("calibrate-kernels");
  auto r = run_cli("kernels --export " + dir + " --for calibrate " + compiled());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string out = path("calib-for-calibrate.yaml");
  r = run_cli(calibrate_args(out) + from_binaries(dir), empty_pocl_cache("for-calibrate"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out));
}

// --for names commands; commands that run no kernels, unknown names, and an export that would
// load binaries instead of building them are usage errors, caught before any device work.
TEST(KernelExport, UsageErrorsExitWith2) {
  test::ScratchDir d;
  const std::string dir = (d / "k").string();
  auto r = run_cli("kernels --export " + dir + " --for posegraph");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("runs no kernels"), std::string::npos) << r.output;
  r = run_cli("kernels --export " + dir + " --for track,flying");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("\"flying\""), std::string::npos) << r.output;
  r = run_cli("kernels --export " + dir + " --kernel-binaries " + dir);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--kernel-binaries"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
}  // namespace planarvo
