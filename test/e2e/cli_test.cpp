// The planarvo tool as a user runs it: exit codes (0 ok, 1 failed, 2 bad usage or input,
// 3 no device) and messages that name the file and line, for each kind of bad input; a track
// stopped by bad input writes nothing. (What the commands print and write is compared with the C
// API in cli_data_test, cli_track_test and cli_graph_test.)
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/capi_util.h"
#include "common/printed_values.h"
#include "common/test_util.h"
#include "io/formats.h"
#include "io/motions.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::run_cli;
using test::ScratchDir;

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

std::string read(const fs::path& p) { return test::read_file(p); }

const char* kCameraYaml =
    "%YAML:1.0\n---\nimage_width: 64\nimage_height: 48\n"
    "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
    "   data: [ 50., 0., 31.5, 0., 50., 23.5, 0., 0., 1. ]\n"
    "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n"
    "   data: [ -0.1, 0.01, 0., 0., 0. ]\n";

// A small valid data set: 3 noise images of 64x48 with frames.txt and odometry.
void make_dataset(const fs::path& dir) {
  write(dir / "camera.yaml", kCameraYaml);
  cv::Mat img(48, 64, CV_8UC1);
  cv::RNG rng(3);
  std::string frames;
  for (int i = 0; i < 3; ++i) {
    rng.fill(img, cv::RNG::UNIFORM, 0, 255);
    fs::create_directories(dir / "images");
    cv::imwrite((dir / "images" / (std::to_string(i) + ".png")).string(), img);
    frames += std::to_string(0.1 * i) + " images/" + std::to_string(i) + ".png\n";
  }
  write(dir / "frames.txt", "# t path\n" + frames);
  write(dir / "odometry.txt", "0.0 0 0 0 0 0 0 1\n0.2 0.1 0 0 0 0 0 1\n");
}

TEST(Cli, UsageErrorsExitWith2) {
  // output unchecked: usage errors below, nothing runs
  EXPECT_EQ(run_cli("").exit_code, 2);
  EXPECT_EQ(run_cli("no-such-command").exit_code, 2);
  auto r = run_cli("simulate --out /tmp/x --no-such-option 1");  // output unchecked: a usage error
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--no-such-option"), std::string::npos) << r.output;
  r = run_cli("simulate --out /tmp/x --seconds abc");  // output unchecked: a usage error
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--seconds"), std::string::npos) << r.output;
  // output unchecked: a usage error
  EXPECT_EQ(run_cli("simulate --out /tmp/x --motion zigzag").exit_code, 2);
  EXPECT_EQ(run_cli("info").exit_code, 2);
}

TEST(Cli, HelpAndVersion) {
  auto r = run_cli("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* cmd : {"demo", "simulate", "info", "devices", "kernels"})
    EXPECT_NE(r.output.find(cmd), std::string::npos) << cmd;
  EXPECT_EQ(run_cli("version").output, "planarvo 0.2.0\n");
  EXPECT_EQ(run_cli("simulate --help").exit_code, 0);
}

TEST(Cli, UnknownDeviceExitsWith3) {
  ScratchDir d;
  auto r = run_cli("simulate --out " + (d / "s").string() + " --device no-such-device-xyz");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("no-such-device-xyz"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(d / "s"));
  r = run_cli("kernels --export " + (d / "k").string() + " --device 99");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_FALSE(fs::exists(d / "k"));
}

// Each bad input: exit code 2, and the message names the file (and line where it applies).
struct BadInput {
  const char* name;
  void (*corrupt)(const fs::path&);
  const char* must_mention;
};

const BadInput kBadInputs[] = {
    {"missing_camera_yaml", [](const fs::path& d) { fs::remove(d / "camera.yaml"); }, "camera.yaml"},
    {"camera_yaml_without_key",
     [](const fs::path& d) { write(d / "camera.yaml", "%YAML:1.0\n---\nimage_width: 64\nimage_height: 48\n"); },
     "camera_matrix"},
    {"missing_frames_txt", [](const fs::path& d) { fs::remove(d / "frames.txt"); }, "frames.txt"},
    {"missing_image", [](const fs::path& d) { fs::remove(d / "images" / "1.png"); }, "1.png"},
    {"unreadable_image", [](const fs::path& d) { write(d / "images" / "2.png", "not a png"); }, "2.png"},
    {"image_of_wrong_size",
     [](const fs::path& d) { cv::imwrite((d / "images" / "1.png").string(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(7))); },
     "1.png"},
    {"non_increasing_timestamps",
     [](const fs::path& d) { write(d / "frames.txt", "0.0 images/0.png\n0.2 images/1.png\n0.1 images/2.png\n"); },
     "frames.txt:3"},
    {"nan_timestamp",
     [](const fs::path& d) { write(d / "frames.txt", "0.0 images/0.png\nnan images/1.png\n"); }, "frames.txt:2"},
    {"inf_in_odometry",
     [](const fs::path& d) { write(d / "odometry.txt", "0.0 0 0 0 0 0 0 1\n0.2 inf 0 0 0 0 0 1\n"); },
     "odometry.txt:2"},
    {"empty_dataset", [](const fs::path& d) { write(d / "frames.txt", "# nothing\n"); }, "frames.txt"},
    {"malformed_direction", [](const fs::path& d) { write(d / "direction.txt", "0.1 +1\n0.2 7\n"); }, "direction.txt:2"},
    {"malformed_extrinsics", [](const fs::path& d) { write(d / "extrinsics.yaml", "%YAML:1.0\n---\nx: 1\n"); },
     "extrinsics.yaml"},
};

class CliBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(CliBadInput, ExitsWith2AndNamesTheFile) {
  ScratchDir d;
  make_dataset(d.path());
  GetParam().corrupt(d.path());
  auto r = run_cli("info --verify " + d.path().string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(GetParam().must_mention), std::string::npos) << r.output;
}

INSTANTIATE_TEST_SUITE_P(All, CliBadInput, ::testing::ValuesIn(kBadInputs),
                         [](const auto& p) { return std::string(p.param.name); });

TEST(Cli, MissingDatasetDirectory) {
  auto r = run_cli("info /nonexistent/planarvo-data");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("/nonexistent/planarvo-data"), std::string::npos) << r.output;
}

TEST(Cli, SimulateRejectsBadTexture) {
  ScratchDir d;
  auto r = run_cli("simulate --quiet --out " + (d / "sim").string() + " --texture /nonexistent/floor.png");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/floor.png"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(d / "sim"));
}

// A car drive for a rear camera: every interval of the written ground truth is an arc no tighter
// than --min-turn-radius (curvature from the true poses, independently of the simulator's
// velocities). A camera tilted until it sees the horizon is refused, and no directory is made.
TEST(Cli, SimulateDrivesACarAndRefusesTheHorizon) {
  ScratchDir d;
  const fs::path seq = d / "car";
  auto r = run_cli("simulate --quiet --out " + seq.string() + " --seconds 3 --width 160 --height 120 --fov 60 "
                   "--extrinsics=-1,0,0.9,0,40,180 --motion car --max-speed 3 --min-turn-radius 6");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<io::StampedPose> gt = io::read_tum((seq / "groundtruth.txt").string());
  ASSERT_EQ(gt.size(), 90u);
  double travelled = 0;
  for (size_t i = 1; i < gt.size(); ++i) {
    const SE2 m = gt[i - 1].pose.inverse() * gt[i].pose;
    const double chord = std::hypot(m.x, m.y);
    travelled += chord;
    // An arc of angle theta and chord c has radius c / (2 sin(theta / 2)).
    if (std::abs(m.theta) > 1e-12) {
      EXPECT_GE(chord / (2 * std::sin(std::abs(m.theta) / 2)), 6.0 * (1 - 1e-6)) << i;
    }
  }
  EXPECT_GT(travelled, 1.0);

  const fs::path bad = d / "horizon";
  r = run_cli("simulate --quiet --out " + bad.string() + " --seconds 1 --width 160 --height 120 --fov 60 "
              "--extrinsics=-1,0,0.9,0,80,180");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(bad));
}

// A rear camera tilted 66 degrees from vertical sees the horizon at the bottom of its image: the
// simulator refuses it, and accepts it with a region of interest that leaves the far field out,
// which it writes into camera.yaml; `track` reads the region from there and follows the drive
// (per-frame motions against the simulator's ground truth); a region outside the image is bad
// input (exit 2).
TEST(Cli, ARegionOfInterestLetsARearCameraSeeTheHorizon) {
  ScratchDir d;
  const std::string cam = " --seconds 3 --width 320 --height 240 --fov 60 --extrinsics=-1,0,0.9,0,66,180 "
                          "--motion car --max-speed 2 --min-turn-radius 6";
  auto r = run_cli("simulate --quiet --out " + (d / "whole").string() + cam);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_FALSE(fs::exists(d / "whole"));
  const fs::path seq = d / "roi";
  r = run_cli("simulate --quiet --out " + seq.string() + cam + " --roi 0,0,320,150");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const CameraModel c = io::read_camera_yaml((seq / "camera.yaml").string());
  EXPECT_EQ(c.roi, (PixelRegion{0, 0, 320, 150}));

  const fs::path traj = d / "traj.txt";
  r = run_cli("track --quiet " + seq.string() + " --extrinsics " + (seq / "extrinsics_gt.yaml").string() + " -o " +
              traj.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<io::StampedPose> est = io::read_tum(traj.string());
  const std::vector<io::StampedPose> gt = io::read_tum((seq / "groundtruth.txt").string());
  ASSERT_EQ(est.size(), gt.size());
  double worst = 0, travelled = 0;
  for (size_t i = 1; i < gt.size(); ++i) {
    const SE2 e = est[i - 1].pose.inverse() * est[i].pose, t = gt[i - 1].pose.inverse() * gt[i].pose;
    worst = std::max(worst, std::hypot(e.x - t.x, e.y - t.y));
    travelled += std::hypot(t.x, t.y);
  }
  EXPECT_GT(travelled, 1.0);
  EXPECT_LT(worst, 1e-3) << "the largest per-frame translation error, metres";

  r = run_cli("track --quiet " + seq.string() + " --extrinsics " + (seq / "extrinsics_gt.yaml").string() +
              " --roi 0,100,320,150");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

// A usage error says what was wrong (exit 2), in the tool's words: the option as typed, the
// argument that is missing or extra; --help alone is exit 0.
TEST(Cli, UsageErrorsSayWhatWasWrong) {
  struct Case { const char* args; const char* says; };
  const Case cases[] = {
      {"track a b", "unexpected argument b"},
      {"track", "missing DATASET"},
      {"info", "missing DATASET"},
      {"posegraph", "missing IN.g2o"},
      {"calibrate", "missing DATASET"},
      {"track d --levels 12", "--levels must be 1 to 8, not 12"},
      {"track d --levels 3 --finest-level 3", "--finest-level must be 0 to 2, not 3"},
      {"track d --levels 4294967297", "--levels must be 1 to 8"},
      {"track d --roi 0,0,100", "--roi needs 4 comma-separated numbers"},
      {"track d --roi 0,0,100.5,100", "--roi needs four non-negative integers"},
      {"calibrate d --roi 5,5,0,0", "--roi: give a width and a height"},
      {"track d --finest-level 0 --level0-subsample 9", "--level0-subsample must be 1 to 8"},
      // Output files never get directories made for them (simulate --out and kernels --export,
      // which name directories, do). output unchecked: the directory does not exist
      {"track d -o /nonexistent-planarvo/t.txt", "-o: the directory /nonexistent-planarvo does not exist"},
      {"track d --stats /nonexistent-planarvo/s.csv", "--stats: the directory /nonexistent-planarvo does not exist"},
      {"calibrate d -o /nonexistent-planarvo/e.yaml", "-o: the directory /nonexistent-planarvo does not exist"},
      {"posegraph in.g2o -o /nonexistent-planarvo/o.g2o", "-o: the directory /nonexistent-planarvo does not exist"},
      {"calibrate --motions m.csv -o /nonexistent-planarvo/e.yaml", "-o: the directory /nonexistent-planarvo does not exist"},
  };
  for (const Case& c : cases) {
    auto r = run_cli(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << ": " << r.output;
    EXPECT_EQ(r.output.find("usage:"), std::string::npos) << c.args << ": " << r.output;
  }
  EXPECT_EQ(run_cli("track --help").exit_code, 0);
}

// A track that stops on a corrupt frame halfway (exit 2) writes nothing and overwrites nothing:
// the user's earlier trajectory, statistics and motions are left byte for byte, and no partial
// file remains. The same run on the intact data set replaces them.
TEST(Cli, TrackStoppedByACorruptFrameLeavesEarlierOutputsAsTheyWere) {
  ScratchDir d;
  const fs::path sim = d / "sim";
  auto r = run_cli("simulate --quiet --out " + sim.string() + " --seconds 0.5 --width 160 --height 120 --seed 5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path traj = d / "traj.txt", stats = d / "stats.csv", motions = d / "motions.csv";
  for (const fs::path& p : {traj, stats, motions}) write(p, "the user's earlier " + p.filename().string() + "\n");
  const std::string cmd = "track " + sim.string() + " --quiet --extrinsics " + (sim / "extrinsics_gt.yaml").string() +
                          " -o " + traj.string() + " --stats " + stats.string() + " --motions-out " + motions.string();
  const std::string intact = read(sim / "images" / "000010.png");
  write(sim / "images" / "000010.png", "not a png");
  r = run_cli(cmd);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("000010.png"), std::string::npos) << r.output;
  for (const fs::path& p : {traj, stats, motions}) {
    EXPECT_EQ(read(p), "the user's earlier " + p.filename().string() + "\n") << p;
    EXPECT_EQ(test::partial_files(p), 0) << p;
  }
  write(sim / "images" / "000010.png", intact);
  r = run_cli(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The trajectory now written is the one the C API tracks on the intact data set.
  planarvo_extrinsics e{};
  ASSERT_EQ(planarvo_extrinsics_load((sim / "extrinsics_gt.yaml").string().c_str(), &e), PLANARVO_OK);
  const std::vector<test::TrackedFrame> frames = test::track_through_api(sim.string(), e);
  const std::vector<io::StampedPose> tum = io::read_tum(traj.string());
  ASSERT_EQ(tum.size(), 15u);
  ASSERT_EQ(frames.size(), 15u);
  for (size_t i = 0; i < tum.size(); ++i) {
    EXPECT_EQ(tum[i].pose.x, frames[i].result.pose.x) << i;
    EXPECT_EQ(tum[i].pose.y, frames[i].result.pose.y) << i;
  }
  EXPECT_EQ(test::read_csv(stats.string()).size(), 15u);
  EXPECT_EQ(io::read_motion_pairs(motions.string()).pairs.size(), 14u);  // one per interval
  for (const fs::path& p : {stats, motions}) {
    EXPECT_NE(read(p).rfind("the user's earlier", 0), 0u) << p;
    EXPECT_EQ(test::partial_files(p), 0) << p;
  }
}

}  // namespace
}  // namespace planarvo
