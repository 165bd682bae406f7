// `planarvo track`, `posegraph` and `calibrate` as a user runs them: outputs, accuracy printout,
// exit codes.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "common/test_util.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::run_cli;
using test::ScratchDir;

int count_lines(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  int n = 0;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') ++n;
  return n;
}

TEST(CliTrack, TracksASimulatedSequenceAndReportsAccuracy) {
  ScratchDir d;
  const std::string seq = (d / "seq").string();
  auto r = run_cli("simulate --quiet --out " + seq + " --seconds 1 --width 320 --height 240 --seed 5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string traj = (d / "traj.txt").string(), stats = (d / "stats.csv").string();
  r = run_cli("track --quiet " + seq + " --extrinsics " + seq + "/extrinsics_gt.yaml -o " + traj + " --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("velocity slope"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("gross (> 1 mm) 0"), std::string::npos) << r.output;
  EXPECT_EQ(count_lines(traj), 30);
  std::ifstream s(stats);
  std::string header;
  std::getline(s, header);
  EXPECT_EQ(header, "timestamp,vx,vy,omega,iterations,final_cost,inlier_fraction,ms,status");
  EXPECT_EQ(count_lines(stats), 31);  // the header and one row per frame
}

TEST(CliTrack, MissingExtrinsicsIsUsageError) {
  ScratchDir d;
  const std::string seq = (d / "seq").string();
  ASSERT_EQ(run_cli("simulate --quiet --out " + seq + " --seconds 0.2 --width 96 --height 64").exit_code, 0);
  auto r = run_cli("track --quiet " + seq);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("extrinsics.yaml"), std::string::npos) << r.output;
}

TEST(CliPosegraph, RingReachesTheReferenceOptimum) {
  ScratchDir d;
  const std::string out = (d / "ring_opt.g2o").string();
  auto r = run_cli("posegraph " + (test::shared_dir() / "data/posegraphs/ring.g2o").string() + " -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("-> 11.163"), std::string::npos) << r.output;
  EXPECT_EQ(count_lines(out), 434 + 459);
  // Optimising the optimum again changes nothing.
  r = run_cli("posegraph " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("chi2 11.163"), std::string::npos) << r.output;
}

TEST(CliPosegraph, BadFileNamesTheLine) {
  ScratchDir d;
  const fs::path bad = d / "bad.g2o";
  std::ofstream(bad) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0\n";
  auto r = run_cli("posegraph " + bad.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.g2o:2"), std::string::npos) << r.output;
}

// A NaN in an edge is bad input like one in a vertex: exit 2 naming the line, no output graph.
TEST(CliPosegraph, NanInAnEdgeIsBadInputAndWritesNothing) {
  ScratchDir d;
  const fs::path bad = d / "bad.g2o", out = d / "out.g2o";
  std::ofstream(bad) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 nan 0 0 1 0 0 1 0 1\n";
  auto r = run_cli("posegraph " + bad.string() + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.g2o:3"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliCalibrate, CensiLmovAgainstOdometry) {
  ScratchDir d;
  const std::string out = (d / "extrinsics.yaml").string();
  auto r = run_cli("calibrate --motions " + (test::shared_dir() / "data/real/censi2011/lmov_motions.csv").string() +
                   " --fix-scale -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(out));
  std::ifstream in(out);
  const std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(yaml.find("z: 0."), std::string::npos) << yaml;  // metric sensor: z written as 0
  EXPECT_NE(yaml.find("estimated"), std::string::npos);
}

TEST(CliCalibrate, NoiseModelOptionsAndTotals) {
  const std::string csv = (test::shared_dir() / "data/real/censi2011/lmov_motions.csv").string();
  auto r = run_cli("calibrate --motions " + csv + " --fix-scale");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("iterations over all solves"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("(0 rejected"), std::string::npos) << r.output;
  r = run_cli("calibrate --motions " + csv + " --fix-scale --gate-sigma 0 --loss none --sensor-sigma 0.01,0.001,0.1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(0 rejected"), std::string::npos) << r.output;
  EXPECT_EQ(run_cli("calibrate --motions " + csv + " --fix-scale --gate-sigma -1").exit_code, 2);
  EXPECT_EQ(run_cli("calibrate --motions " + csv + " --fix-scale --loss l2").exit_code, 2);
  EXPECT_EQ(run_cli("calibrate --motions " + csv + " --fix-scale --odometry-sigma 0,0,1").exit_code, 2);
}

TEST(CliCalibrate, StraightDrivingIsUnobservableExit1AndNoFile) {
  ScratchDir d;
  const fs::path csv = d / "straight.csv";
  {
    std::ofstream o(csv);
    o << "# interval_s,odo_dx,odo_dy,odo_dtheta,sensor_dx,sensor_dy,sensor_dtheta\n";
    for (int i = 0; i < 200; ++i) {
      const double dx = (i % 40 < 20 ? 1 : -1) * 0.01;
      // The sensor at yaw 90 deg sees the forward motion as motion to its right.
      o << "0.1," << dx << ",0,0,0," << -dx << ",0\n";
    }
  }
  const std::string out = (d / "e.yaml").string();
  auto r = run_cli("calibrate --motions " + csv.string() + " --fix-scale -o " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_NE(r.output.find("straight"), std::string::npos) << r.output;
}

TEST(CliCalibrate, NonholonomicNeedsAScale) {
  auto r = run_cli("calibrate --method nonholonomic --motions " +
                   (test::shared_dir() / "data/real/censi2011/lmov_motions.csv").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--height"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace planarvo
