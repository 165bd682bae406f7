// Bad images in a data set (issue 9): without --skip-bad-frames a missing or undecodable image
// stops `planarvo track` with exit 2 naming the frame's file, and nothing is written; with it,
// the frames are gaps: no pose, a "skipped" statistics row, and the rest tracked, checked
// against the simulator's ground truth. And good images of a floor without texture (issue 8):
// Lost frames, counted in frames and seconds, and exit 1 over --max-lost.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/printed_values.h"
#include "common/test_util.h"
#include "io/formats.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::run_cli;

std::string quoted(const fs::path& p) { return "\"" + p.string() + "\""; }

// The timestamps of the statistics rows whose status (the last column) is `status`.
std::vector<double> stats_times(const fs::path& csv, const std::string& status) {
  std::vector<double> times;
  for (const std::vector<std::string>& row : test::read_csv(csv.string()))
    if (row.size() > 8 && row[8] == status) times.push_back(std::stod(row[0]));
  return times;
}

TEST(CliBadFrames, AreAnErrorUnlessSkippedThenGaps) {
  test::ScratchDir d;
  const fs::path seq = d / "seq";
  auto r = run_cli("simulate --quiet --seconds 1 --width 160 --height 120 --seed 3 --out " + quoted(seq));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<io::FrameEntry> frames = io::read_frames((seq / "frames.txt").string());
  ASSERT_GE(frames.size(), 25u);
  const size_t missing = 8, corrupt = 17;
  fs::remove(seq / frames[missing].path);
  std::ofstream(seq / frames[corrupt].path) << "not an image";

  const fs::path traj = d / "traj.txt", stats = d / "stats.csv";
  const std::string cmd = "track --quiet " + quoted(seq) + " --extrinsics " + quoted(seq / "extrinsics_gt.yaml") +
                          " -o " + quoted(traj) + " --stats " + quoted(stats);
  r = run_cli(cmd);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(fs::path(frames[missing].path).filename().string()), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(traj));
  EXPECT_FALSE(fs::exists(stats));

  r = run_cli(cmd + " --skip-bad-frames");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The trajectory: every frame but the two, at their times.
  const std::vector<io::StampedPose> est = io::read_tum(traj.string());
  ASSERT_EQ(est.size(), frames.size() - 2);
  for (size_t i = 0, k = 0; i < frames.size(); ++i) {
    if (i == missing || i == corrupt) continue;
    EXPECT_NEAR(est[k++].t, frames[i].t, 1e-6) << "frame " << i;
  }
  // The statistics: the two as "skipped" rows at their times.
  const std::vector<double> skipped = stats_times(stats, "skipped");
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_NEAR(skipped[0], frames[missing].t, 1e-6);
  EXPECT_NEAR(skipped[1], frames[corrupt].t, 1e-6);
  // Tracked across the gaps: the poses against the ground truth, relative to the first frame.
  const std::vector<io::StampedPose> truth = io::read_tum((seq / "groundtruth.txt").string());
  ASSERT_EQ(truth.size(), frames.size());
  const SE2 first = truth.front().pose.inverse();
  for (size_t i = 0, k = 0; i < frames.size(); ++i) {
    if (i == missing || i == corrupt) continue;
    const SE2 t = first * truth[i].pose;
    const SE2& e = est[k++].pose;
    EXPECT_NEAR(e.x, t.x, 2e-3) << "frame " << i;
    EXPECT_NEAR(e.y, t.y, 2e-3) << "frame " << i;
    EXPECT_NEAR(e.theta, t.theta, 2e-3) << "frame " << i;
  }
}

// A JPEG cut to a third (a copy interrupted, a card full): libjpeg decodes it with a warning
// and grey rows where the data stop, so it passed `info --verify` and `track` and the tracker
// lost frames on it (issue 27). It is a bad image now: exit 2 naming it, a gap with
// --skip-bad-frames. The same for a PNG cut short.
TEST(CliBadFrames, AnImageCutShortIsABadImage) {
  test::ScratchDir d;
  const fs::path seq = d / "seq";
  auto r = run_cli("simulate --quiet --seconds 0.5 --width 160 --height 120 --seed 4 --out " + quoted(seq));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<io::FrameEntry> frames = io::read_frames((seq / "frames.txt").string());
  std::ofstream list(seq / "frames.txt");
  for (io::FrameEntry& f : frames) {
    const fs::path jpg = fs::path(f.path).replace_extension(".jpg");
    ASSERT_TRUE(cv::imwrite((seq / jpg).string(), cv::imread((seq / f.path).string(), cv::IMREAD_GRAYSCALE)));
    f.path = jpg.string();
    list << f.t << " " << f.path << "\n";
  }
  list.close();
  const fs::path traj = d / "traj.txt", stats = d / "stats.csv";
  const std::string track = "track --quiet " + quoted(seq) + " --extrinsics " + quoted(seq / "extrinsics_gt.yaml") +
                            " -o " + quoted(traj) + " --stats " + quoted(stats);
  r = run_cli("info --verify " + quoted(seq));
  ASSERT_EQ(r.exit_code, 0) << r.output;  // whole JPEGs are fine

  const size_t cut = 6;
  const fs::path cut_file = seq / frames[cut].path;
  fs::resize_file(cut_file, fs::file_size(cut_file) / 3);
  for (const std::string& cmd : {"info --verify " + quoted(seq), track}) {
    r = run_cli(cmd);
    EXPECT_EQ(r.exit_code, 2) << cmd << "\n" << r.output;
    EXPECT_NE(r.output.find(cut_file.filename().string()), std::string::npos) << r.output;
  }
  r = run_cli(track + " --skip-bad-frames");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<double> skipped = stats_times(stats, "skipped");
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NEAR(skipped[0], frames[cut].t, 1e-6);
  EXPECT_EQ(io::read_tum(traj.string()).size(), frames.size() - 1);

  // A PNG cut short: the same refusal.
  const fs::path png = d / "cut.png";
  ASSERT_TRUE(cv::imwrite(png.string(), cv::imread(cut_file.string().replace(cut_file.string().size() - 4, 4, ".png"),
                                                   cv::IMREAD_GRAYSCALE)));
  fs::resize_file(png, fs::file_size(png) / 3);
  fs::copy_file(png, seq / frames[cut].path, fs::copy_options::overwrite_existing);
  r = run_cli("info --verify " + quoted(seq));
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

// Two seconds of a textureless floor in the middle of a drive: a camera's image of flat grey
// with its pixel noise (1 grey level), valid images, so no error. Every one of those frames is
// Lost; so is the first textured frame after them when the robot has moved on from the keyframe
// (its interval spans the gap: nothing measures it); no other frame is. The summary counts them
// in frames and seconds; 33 % lost is over the default --max-lost 5 %: exit 1, with the
// trajectory and the statistics complete. With --max-lost 50 the same run is exit 0.
TEST(CliBadFrames, TwoTexturelessSecondsAreLostCountedAndExit1) {
  test::ScratchDir d;
  const fs::path seq = d / "seq";
  auto r = run_cli("simulate --quiet --seconds 6 --width 160 --height 120 --seed 4 --out " + quoted(seq));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<io::FrameEntry> frames = io::read_frames((seq / "frames.txt").string());
  ASSERT_EQ(frames.size(), 180u);
  std::vector<bool> flat(frames.size(), false);
  cv::RNG rng(7);
  for (size_t i = 0; i < frames.size(); ++i) {
    if (!(frames[i].t >= 2.0 && frames[i].t < 4.0)) continue;
    flat[i] = true;
    cv::Mat noise(120, 160, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 128.0, 1.0);
    cv::Mat image;
    noise.convertTo(image, CV_8U);
    ASSERT_TRUE(cv::imwrite((seq / frames[i].path).string(), image));
  }
  const size_t n_flat = static_cast<size_t>(std::count(flat.begin(), flat.end(), true));
  ASSERT_EQ(n_flat, 60u);

  const fs::path traj = d / "traj.txt", stats = d / "stats.csv";
  const std::string cmd = "track --quiet " + quoted(seq) + " --extrinsics " + quoted(seq / "extrinsics_gt.yaml") +
                          " -o " + quoted(traj) + " --stats " + quoted(stats);
  r = run_cli(cmd);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  // Complete outputs: a pose per frame, a statistics row per frame.
  EXPECT_EQ(io::read_tum(traj.string()).size(), frames.size());
  const std::vector<double> lost = stats_times(stats, "lost");
  std::vector<bool> is_lost(frames.size(), false);
  for (double t : lost)
    for (size_t i = 0; i < frames.size(); ++i)
      if (std::abs(frames[i].t - t) < 1e-6) is_lost[i] = true;
  size_t first_after = 0;
  while (first_after < frames.size() && !(first_after > 0 && flat[first_after - 1] && !flat[first_after])) ++first_after;
  ASSERT_LT(first_after, frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    if (flat[i]) {
      EXPECT_TRUE(is_lost[i]) << "textureless frame " << i << " not lost";
    } else if (i != first_after) {
      EXPECT_FALSE(is_lost[i]) << "textured frame " << i << " lost";
    }
  }
  ASSERT_TRUE(lost.size() == n_flat || lost.size() == n_flat + 1) << lost.size();
  // The summary: the count, the share and the time, against the frames' own timestamps.
  double seconds = 0;
  for (size_t i = 1; i < frames.size(); ++i)
    if (is_lost[i]) seconds += frames[i].t - frames[i - 1].t;
  const std::vector<double> printed = test::numbers_after(r.output, "lost frames:");
  ASSERT_GE(printed.size(), 4u) << r.output;
  EXPECT_EQ(printed[0], static_cast<double>(lost.size()));
  EXPECT_EQ(printed[1], static_cast<double>(frames.size()));
  test::expect_printed(printed[2], 100.0 * static_cast<double>(lost.size()) / static_cast<double>(frames.size()), 1,
                       "lost percentage");
  test::expect_printed(printed[3], seconds, 3, "lost seconds");

  r = run_cli(cmd + " --max-lost 50");
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

}  // namespace
}  // namespace planarvo
