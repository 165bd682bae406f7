// Bad images in a data set (issue 9): without --skip-bad-frames a missing or undecodable image
// stops `planarvo track` with exit 2 naming the frame's file, and nothing is written; with it,
// the frames are gaps: no pose, a "skipped" statistics row, and the rest tracked, checked
// against the simulator's ground truth.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/test_util.h"
#include "io/formats.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::run_cli;

std::string quoted(const fs::path& p) { return "\"" + p.string() + "\""; }

// The timestamps of the statistics rows whose status (the last column) is `status`.
std::vector<double> stats_times(const fs::path& csv, const std::string& status) {
  std::ifstream in(csv);
  std::string line;
  std::vector<double> times;
  std::getline(in, line);  // header
  while (std::getline(in, line))
    if (line.size() > status.size() && line.compare(line.size() - status.size(), status.size(), status) == 0)
      times.push_back(std::stod(line.substr(0, line.find(','))));
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

}  // namespace
}  // namespace planarvo
