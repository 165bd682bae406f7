// The simulator's real-camera geometry (simulator_shutter.cpp): pose_at between frames, the
// rolling shutter (each row of render_frame is a global-shutter render at that row's read time),
// the exposure (the mean of renders at the sub-exposure times), the number of sub-renders, and
// the options' checks. Every expectation is against an independent computation: SE(2) arcs as
// 3x3 matrices, Renderer::render_float at explicitly computed poses, image speeds of a camera
// looking straight down.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "core/error.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"

namespace planarvo::sim {
namespace {

using ::testing::HasSubstr;

cv::Mat noise_texture(int w, int h, uint64_t seed) {
  Random r(seed);
  cv::Mat t(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) t.at<float>(y, x) = static_cast<float>(255.0 * r.uniform());
  return t;
}

// A small camera on the default mount; 2 s of straight driving at up to 0.8 m/s.
Options small_options() {
  Options o;
  o.camera = default_camera(160, 120);
  o.supersampling = 2;
  o.seconds = 2.0;
  o.motion = MotionProfile::Mixed;
  o.seed = 4;
  return o;
}

// The frame whose neighbouring intervals move the image fastest.
size_t fastest_frame(const Options& o, const Trajectory& tr) {
  size_t best = 1;
  double fastest = -1;
  for (size_t k = 1; k + 1 < tr.t.size(); ++k) {
    const double s = std::min(image_speed(o, tr.velocity[k - 1]), image_speed(o, tr.velocity[k]));
    if (s > fastest) {
      fastest = s;
      best = k;
    }
  }
  return best;
}

// exp of the se(2) twist (v, 0, w) for time s as a 3x3 matrix, written out independently of SE2.
Eigen::Matrix3d arc(double v, double w, double s) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  const double a = w * s;
  m(0, 0) = std::cos(a); m(0, 1) = -std::sin(a);
  m(1, 0) = std::sin(a); m(1, 1) = std::cos(a);
  if (std::abs(w) < 1e-12) {
    m(0, 2) = v * s;
  } else {
    m(0, 2) = v / w * std::sin(a);
    m(1, 2) = v / w * (1 - std::cos(a));
  }
  return m;
}

void expect_pose_near(const SE2& got, const Eigen::Matrix3d& want, double tol, const std::string& what) {
  EXPECT_NEAR(got.x, want(0, 2), tol) << what;
  EXPECT_NEAR(got.y, want(1, 2), tol) << what;
  EXPECT_NEAR(std::remainder(got.theta - std::atan2(want(1, 0), want(0, 0)), 2 * M_PI), 0.0, tol) << what;
}

double max_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  double worst = 0;
  for (int y = 0; y < a.rows; ++y)
    for (int x = 0; x < a.cols; ++x)
      worst = std::max(worst, std::abs(static_cast<double>(a.at<float>(y, x)) - b.at<float>(y, x)));
  return worst;
}

TEST(SimShutter, PoseAtIsExactAtFramesAndAnArcBetween) {
  Options o = small_options();
  const Trajectory tr = generate_trajectory(o);
  const double dt = 1.0 / o.fps;
  for (size_t k = 0; k < tr.t.size(); ++k) {
    const SE2 p = pose_at(tr, tr.t[k]);
    ASSERT_EQ(p.x, tr.pose[k].x) << k;
    ASSERT_EQ(p.y, tr.pose[k].y) << k;
    ASSERT_EQ(p.theta, tr.pose[k].theta) << k;
  }
  for (size_t k = 0; k + 1 < tr.t.size(); ++k) {
    const double v = tr.velocity[k].x(), w = tr.velocity[k].y();
    for (double f : {0.25, 0.5, 0.9}) {
      expect_pose_near(pose_at(tr, tr.t[k] + f * dt), tr.pose[k].matrix() * arc(v, w, f * dt), 1e-12,
                       "frame " + std::to_string(k) + " + " + std::to_string(f));
    }
    // Continuous into the next frame.
    expect_pose_near(pose_at(tr, tr.t[k + 1] - 1e-12), tr.pose[k + 1].matrix(), 1e-11, "end of " + std::to_string(k));
  }
  // Standing before the first frame; the last velocity continued after the last.
  const SE2 before = pose_at(tr, -0.5);
  EXPECT_EQ(before.x, tr.pose[0].x);
  EXPECT_EQ(before.y, tr.pose[0].y);
  EXPECT_EQ(before.theta, tr.pose[0].theta);
  const Eigen::Vector2d last = tr.velocity.back();
  expect_pose_near(pose_at(tr, tr.t.back() + 0.02), tr.pose.back().matrix() * arc(last.x(), last.y(), 0.02), 1e-12,
                   "after the last frame");
}

// Row r of a rolling-shutter frame is row r of the global-shutter render at the pose at
// t_k + r / (H - 1) * readout.
TEST(SimShutter, RollingShutterRowsAreRendersAtTheirReadTimes) {
  ocl::Runtime rt;
  Options o = small_options();
  o.readout_time = 0.03;
  const Trajectory tr = generate_trajectory(o);
  Renderer renderer(rt, noise_texture(256, 256, 8), o);
  const size_t k = fastest_frame(o, tr);
  const int H = o.camera.height;
  const cv::Mat frame = render_frame(renderer, o, tr, k);
  ASSERT_EQ(frame.type(), CV_32FC1);
  ASSERT_EQ(frame.size(), cv::Size(o.camera.width, H));
  for (int r : {0, 1, 37, 60, H - 2, H - 1}) {
    const double t = tr.t[k] + static_cast<double>(r) / (H - 1) * o.readout_time;
    const cv::Mat global = renderer.render_float(pose_at(tr, t));
    EXPECT_LT(max_abs_diff(frame.row(r), global.row(r)), 1e-3) << "row " << r;
  }
  // Not vacuous: the last row is read 30 ms after the stamp, and differs from the stamp's render.
  const cv::Mat at_stamp = renderer.render_float(tr.pose[k]);
  EXPECT_EQ(max_abs_diff(frame.row(0), at_stamp.row(0)), 0.0);
  EXPECT_GT(max_abs_diff(frame.row(H - 1), at_stamp.row(H - 1)), 20.0);
  // Without readout or exposure it is the global render, bit for bit.
  Options global = o;
  global.readout_time = 0;
  EXPECT_EQ(max_abs_diff(render_frame(renderer, global, tr, k), at_stamp), 0.0);
}

// A robot standing still: any exposure renders what an instant does.
TEST(SimShutter, ExposureOfAStandingRobotIsTheInstantaneousRender) {
  ocl::Runtime rt;
  Options o = small_options();
  o.exposure_time = 0.02;
  o.readout_time = 0.01;
  Trajectory tr;
  const SE2 p(1.5, -0.3, 0.7);
  tr.t = {0.0, 1 / 30.0, 2 / 30.0};
  tr.pose = {p, p, p};
  tr.velocity = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  tr.direction = {0, 0};
  tr.odometry = tr.pose;
  Renderer renderer(rt, noise_texture(256, 256, 2), o);
  EXPECT_EQ(exposure_samples(o, tr, 1), 1);
  EXPECT_LT(max_abs_diff(render_frame(renderer, o, tr, 1), renderer.render_float(p)), 1e-4);
}

// With motion, the exposed frame is the mean of renders at the midpoints of N equal parts of
// [t_row - E, t_row]: the whole image for a global shutter, row by row for a rolling one.
TEST(SimShutter, ExposureIsTheMeanOfRendersAtTheSubTimes) {
  ocl::Runtime rt;
  Options o = small_options();
  o.exposure_time = 0.012;
  const Trajectory tr = generate_trajectory(o);
  Renderer renderer(rt, noise_texture(256, 256, 3), o);
  const size_t k = fastest_frame(o, tr);
  const int n = exposure_samples(o, tr, k);
  ASSERT_GT(n, 2);
  const double E = o.exposure_time;
  cv::Mat mean = cv::Mat::zeros(o.camera.height, o.camera.width, CV_64FC1);
  for (int i = 0; i < n; ++i) {
    cv::Mat f, d;
    f = renderer.render_float(pose_at(tr, tr.t[k] - E + (i + 0.5) * E / n));
    f.convertTo(d, CV_64F, 1.0 / n);
    mean += d;
  }
  cv::Mat mean_f;
  mean.convertTo(mean_f, CV_32F);
  const cv::Mat exposed = render_frame(renderer, o, tr, k);
  EXPECT_LT(max_abs_diff(exposed, mean_f), 2e-3);
  // Not vacuous: the blur changes the image.
  EXPECT_GT(max_abs_diff(exposed, renderer.render_float(tr.pose[k])), 10.0);

  // Rolling shutter and exposure together, row by row.
  o.readout_time = 0.025;
  const int H = o.camera.height;
  const int nr = exposure_samples(o, tr, k);
  ASSERT_GE(nr, n);
  const cv::Mat both = render_frame(renderer, o, tr, k);
  for (int r : {0, 59, H - 1}) {
    const double t_row = tr.t[k] + static_cast<double>(r) / (H - 1) * o.readout_time;
    cv::Mat row_mean = cv::Mat::zeros(1, o.camera.width, CV_64FC1);
    for (int i = 0; i < nr; ++i) {
      cv::Mat d;
      renderer.render_float(pose_at(tr, t_row - E + (i + 0.5) * E / nr)).row(r).convertTo(d, CV_64F, 1.0 / nr);
      row_mean += d;
    }
    cv::Mat row_f;
    row_mean.convertTo(row_f, CV_32F);
    EXPECT_LT(max_abs_diff(both.row(r), row_f), 2e-3) << "row " << r;
  }
}

// image_speed against a pinhole camera looking straight down from height h: driving at v moves
// every pixel at f v / h; turning at w about the camera's own centre turns the image about the
// principal point, a pixel p at w |p - c|.
TEST(SimShutter, ImageSpeedOfACameraLookingStraightDown) {
  Options o;
  o.camera.width = 200;
  o.camera.height = 150;
  o.camera.fx = o.camera.fy = 180.0;
  o.camera.cx = 99.5;
  o.camera.cy = 74.5;
  o.extrinsics = Extrinsics{0.0, 0.0, 0.5, 0.0, 0.0, 0.0};
  EXPECT_EQ(image_speed(o, Eigen::Vector2d(0, 0)), 0.0);
  EXPECT_NEAR(image_speed(o, Eigen::Vector2d(0.8, 0)), 180.0 * 0.8 / 0.5, 1e-4);
  EXPECT_NEAR(image_speed(o, Eigen::Vector2d(-0.3, 0)), 180.0 * 0.3 / 0.5, 1e-4);
  EXPECT_NEAR(image_speed(o, Eigen::Vector2d(0, 1.5)), 1.5 * std::hypot(99.5, 74.5), 1e-3);

  // The number of sub-renders: ceil(2 s E), at least 1, at most 64.
  Options d = small_options();
  const Trajectory tr = generate_trajectory(d);
  const size_t k = fastest_frame(d, tr);
  // A global shutter's exposure [t_k - E, t_k] lies in interval k - 1 alone.
  const double s = image_speed(d, tr.velocity[k - 1]);
  d.exposure_time = 0.004;
  EXPECT_EQ(exposure_samples(d, tr, k), std::clamp(static_cast<int>(std::ceil(2 * s * 0.004)), 1, 64));
  d.exposure_time = 1.0 / 30;
  EXPECT_LE(exposure_samples(d, tr, k), 64);
  d.exposure_time = 0;
  EXPECT_EQ(exposure_samples(d, tr, k), 1);
}

// The blur a 4 ms exposure gives at the default camera's top speeds (reported in SIMULATOR.md).
TEST(SimShutter, DefaultCameraBlurAtTopSpeed) {
  const Options o;
  const double drive = image_speed(o, Eigen::Vector2d(o.max_speed, 0)) * 0.004;
  const double turn = image_speed(o, Eigen::Vector2d(0, o.max_turn_rate)) * 0.004;
  std::printf("4 ms exposure, default camera: %.2f px at %.1f m/s, %.2f px turning at %.1f rad/s\n", drive,
              o.max_speed, turn, o.max_turn_rate);
  EXPECT_GT(drive, 1.0);
  EXPECT_GT(turn, 1.0);
}

TEST(SimShutter, OptionsAreChecked) {
  const auto refused = [](const char* field, double value, double Options::*member, const char* says) {
    Options o;
    o.texture = "unused.png";
    o.*member = value;
    try {
      validate(o);
      ADD_FAILURE() << field << " = " << value << " was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidArgument) << field;
      EXPECT_THAT(e.what(), HasSubstr(says)) << field << " = " << value;
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  refused("readout_time", -0.001, &Options::readout_time, "readout_time");
  refused("readout_time", nan, &Options::readout_time, "readout_time");
  refused("readout_time", 0.034, &Options::readout_time, "1 / fps");
  refused("exposure_time", -0.001, &Options::exposure_time, "exposure_time");
  refused("exposure_time", std::numeric_limits<double>::infinity(), &Options::exposure_time, "exposure_time");
  refused("exposure_time", 0.034, &Options::exposure_time, "1 / fps");
  Options ok;
  ok.readout_time = 1.0 / 30;
  ok.exposure_time = 1.0 / 30;
  EXPECT_NO_THROW(validate(ok));
  // The camera model refuses a negative readout of its own (InvalidInput, naming what).
  CameraModel c = default_camera();
  c.rolling_shutter_readout = -0.01;
  try {
    c.validate("my camera");
    ADD_FAILURE() << "a negative rolling_shutter_readout was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidInput);
    EXPECT_THAT(e.what(), HasSubstr("my camera"));
    EXPECT_THAT(e.what(), HasSubstr("rolling_shutter_readout"));
  }
  c.rolling_shutter_readout = nan;
  EXPECT_THROW(c.validate("my camera"), Error);
}

}  // namespace
}  // namespace planarvo::sim
