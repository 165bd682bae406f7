// Motion-pair CSV (formats.md): the real Censi files, round trips, labels from odometry, and
// malformed files naming file and line.
#include <fstream>

#include <gtest/gtest.h>

#include "common/test_util.h"
#include "core/error.h"
#include "io/motions.h"

namespace planarvo::io {
namespace {

using test::ScratchDir;

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(IoMotions, ReadsTheCensiFiles) {
  const auto m = read_motion_pairs((test::shared_dir() / "data/real/censi2011/lmov_motions.csv").string());
  EXPECT_TRUE(m.has_odometry);
  EXPECT_FALSE(m.has_direction_column);
  ASSERT_GT(m.pairs.size(), 100u);
  const MotionPair& p = m.pairs.front();  // 0.805137,0.00837124346,3.82902531e-06,...
  EXPECT_DOUBLE_EQ(p.interval, 0.805137);
  EXPECT_DOUBLE_EQ(p.odometry->value.x, 0.00837124346);
  EXPECT_DOUBLE_EQ(p.sensor.value.theta, -0.00353017);
  EXPECT_FALSE(p.sensor.has_covariance());
  EXPECT_EQ(*p.direction, 1);
}

TEST(IoMotions, LabelsFromOdometrySign) {
  ScratchDir d;
  const std::string path = (d / "m.csv").string();
  write(path, "# interval_s, odo_dx, odo_dy, odo_dtheta, sensor_dx, sensor_dy, sensor_dtheta\n"
              "1.0, 0.1, 0, 0, 0.1, 0, 0\n"
              "1.0, -0.1, 0, 0, -0.1, 0, 0\n"
              "1.0, 0.0005, 0, 0.3, 0, 0, 0.3\n");
  const auto m = read_motion_pairs(path);
  ASSERT_EQ(m.pairs.size(), 3u);
  EXPECT_EQ(*m.pairs[0].direction, 1);
  EXPECT_EQ(*m.pairs[1].direction, -1);
  EXPECT_EQ(*m.pairs[2].direction, 0);  // 0.5 mm/s is below the 1 mm/s default
}

TEST(IoMotions, SensorOnlyWithDirectionColumnRoundTrips) {
  ScratchDir d;
  const std::string path = (d / "m.csv").string();
  std::vector<MotionPair> in(2);
  in[0] = {0.1, std::nullopt, Motion{SE2(0.01, 0.002, 0.1)}, 1};
  in[1] = {0.2, std::nullopt, Motion{SE2(-0.01, 1e-17, -0.3)}, 0};
  write_motion_pairs(path, in);
  const auto m = read_motion_pairs(path);
  EXPECT_FALSE(m.has_odometry);
  EXPECT_TRUE(m.has_direction_column);
  ASSERT_EQ(m.pairs.size(), 2u);
  EXPECT_EQ(m.pairs[1].sensor.value.y, 1e-17);
  EXPECT_EQ(*m.pairs[1].direction, 0);
  EXPECT_FALSE(m.pairs[0].odometry.has_value());
}

TEST(IoMotions, MalformedFilesNameFileAndLine) {
  ScratchDir d;
  const std::string path = (d / "bad.csv").string();
  auto expect_error = [&](const std::string& text, const std::string& mention) {
    write(path, text);
    try {
      read_motion_pairs(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidInput);
      EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
    }
  };
  const std::string h = "# interval_s,sensor_dx,sensor_dy,sensor_dtheta\n";
  expect_error("0.1,0,0,0\n", "bad.csv:1");                      // no header
  expect_error("# interval_s,sensor_dx,sensor_dy\n0.1,0,0\n", "sensor_dtheta");
  expect_error("# interval_s,odo_dx,sensor_dx,sensor_dy,sensor_dtheta\n", "come together");
  expect_error("# interval_s,sensor_dx,sensor_dy,sensor_dtheta,speed\n", "speed");
  expect_error(h + "0.1,0,0,0\n0.1,0,nan,0\n", "bad.csv:3");
  expect_error(h + "0.1,0,0\n", "bad.csv:2");
  // Beyond 1e6 m: a corrupt value or another unit (issue 27).
  expect_error(h + "0.1,0,0,0\n0.1,1e308,0,0\n", "bad.csv:3");
  expect_error("# interval_s,odo_dx,odo_dy,odo_dtheta,sensor_dx,sensor_dy,sensor_dtheta\n0.1,0,-2e6,0,0,0,0\n",
               "bad.csv:2");
  expect_error(h + "-0.1,0,0,0\n", "bad.csv:2");
  expect_error(h, "no motion pairs");
  expect_error("# interval_s,sensor_dx,sensor_dy,sensor_dtheta,direction\n0.1,0,0,0,2\n", "bad.csv:2");
  expect_error("", "header");
}

}  // namespace
}  // namespace planarvo::io
