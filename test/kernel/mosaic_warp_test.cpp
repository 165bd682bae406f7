// kernels/mosaic/mosaic.cl against its plain C++ reference (mosaic_warp_reference), on random frames,
// cameras (distortion, regions of interest), extrinsics, poses, resolutions and windows; and the
// reference's geometry against the camera model: a frame rendered from a known ground pattern
// through CameraModel::unproject (Newton's method on the distortion, in double) must warp back
// to that pattern at every mosaic pixel it gives weight to.
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "common/random_scene.h"
#include "mosaic/mosaic_warp.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"

namespace planarvo::mosaic {
namespace {

// The render test's random camera, and half of the time a region of interest.
CameraModel random_camera(sim::Random& r, int w, int h) {
  CameraModel c = test::random_camera(r, w, h);
  if (r.uniform() < 0.5) c.roi = {static_cast<int>(r.uniform(0, 20)), static_cast<int>(r.uniform(0, 20)), w - 40, h - 30};
  return c;
}

using test::random_extrinsics;

cv::Mat noise_frame(sim::Random& r, int w, int h) {
  cv::Mat f(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) f.at<uint8_t>(y, x) = static_cast<uint8_t>(255.0 * r.uniform());
  return f;
}

// A grid far from the origin (float precision of the homography is part of what is tested) and a
// window around the camera's foot point.
struct Case {
  WarpSetup setup;
  SE2 pose;
  MosaicGrid grid;
  Window window;
};

Case random_case(sim::Random& r, int w, int h) {
  Case c;
  const CameraModel cam = random_camera(r, w, h);
  const Extrinsics e = random_extrinsics(r, 35.0);
  c.setup = make_warp_setup(cam, e, r.uniform(1.0, 5.0) * e.z, r.uniform(5.0, 100.0));
  c.pose = SE2(r.uniform(-50, 50), r.uniform(-50, 50), r.uniform(-M_PI, M_PI));
  c.grid.resolution = r.uniform(0.0005, 0.004);
  c.grid.width = c.grid.height = 20000;
  const Eigen::Vector2d foot = c.pose * Eigen::Vector2d(e.x, e.y);
  c.grid.origin = foot - Eigen::Vector2d(r.uniform(5, 15), r.uniform(5, 15)) * c.grid.resolution * 1000.0;
  const double col = (foot.x() - c.grid.origin.x()) / c.grid.resolution;
  const double row = c.grid.height - (foot.y() - c.grid.origin.y()) / c.grid.resolution;
  const int half = std::min(450, static_cast<int>(2.0 * e.z / c.grid.resolution));
  c.window = {static_cast<int>(col) - half, static_cast<int>(row) - half, 2 * half + static_cast<int>(r.uniform(0, 7)),
              2 * half + static_cast<int>(r.uniform(0, 7))};
  return c;
}

// Fast for a camera at height z: 10 z per second forward (3 m/s at 0.3 m: 0.3 z over a 30 ms
// readout, as much of the ground in view as on a robot at 3 m/s) while turning at 1.5 rad/s.
Eigen::Vector3d fast_velocity(const Extrinsics& e) { return {10.0 * e.z, 0.0, 1.5}; }

// The robot's poses when a frame's first, middle and last rows were read, at that velocity from
// `pose`.
std::array<SE2, 3> fast_readout_poses(const Extrinsics& e, const SE2& pose, double readout) {
  const Eigen::Vector3d velocity = fast_velocity(e);
  return {pose, pose * SE2::exp(0.5 * readout * velocity), pose * SE2::exp(readout * velocity)};
}

TEST(MosaicWarpKernel, MatchesReference) {
  ocl::Runtime runtime;
  sim::Random r(31);
  for (const auto& [w, h] : {std::pair{640, 480}, std::pair{161, 97}, std::pair{64, 48}}) {
    MosaicWarp warp(runtime, w, h);
    for (int trial = 0; trial < 6; ++trial) {
      Case c = random_case(r, w, h);
      const cv::Mat frame = noise_frame(r, w, h);
      // Stale values: a run with another pose first, so an element the kernel does not write
      // keeps a value the reference does not give.
      cv::Mat out;
      Case other = c;
      other.pose = SE2(c.pose.x + 0.01, c.pose.y, c.pose.theta + 0.3);
      warp.run(255 - frame, warp_params(other.setup, other.pose, other.grid, other.window), c.window.width,
               c.window.height, &out);
      // Every other trial a rolling shutter read out over 30 ms while driving fast (the first and
      // last rows' poses 0.3 camera heights and 2.6 degrees apart).
      const bool rolling = trial % 2 == 1;
      if (rolling) c.setup.camera.rolling_shutter_readout = 0.03;
      const WarpParams prm =
          rolling ? warp_params(c.setup, fast_readout_poses(c.setup.extrinsics, c.pose, 0.03), c.grid, c.window)
                  : warp_params(c.setup, c.pose, c.grid, c.window);
      warp.run(frame, prm, c.window.width, c.window.height, &out);
      const cv::Mat ref = mosaic_warp_reference(frame, prm, c.window.width, c.window.height);
      int seen = 0, validity_flips = 0;
      double worst_value = 0, worst_weight = 0;
      for (int y = 0; y < ref.rows; ++y)
        for (int x = 0; x < ref.cols; ++x) {
          const cv::Vec2f a = out.at<cv::Vec2f>(y, x), b = ref.at<cv::Vec2f>(y, x);
          if ((a[1] > 0) != (b[1] > 0)) {
            ++validity_flips;  // a sample within float rounding of a border of the domain
            continue;
          }
          if (b[1] > 0) ++seen;
          worst_value = std::max(worst_value, static_cast<double>(std::abs(a[0] - b[0])));
          worst_weight = std::max(worst_weight, static_cast<double>(std::abs(a[1] - b[1])));
        }
      // The kernel does the reference's float operations (up to fused multiply-adds): frame
      // coordinates agree to about 1e-4 px, so a value to 255 * 1e-4 on a noise frame. With a
      // rolling shutter the kernel's secant steps against the reference's fixed-point iteration
      // to convergence: within 0.01 px (0.006 measured), a value within 2.5 on a noise frame.
      EXPECT_LT(worst_value, rolling ? 2.5 : 0.05) << w << "x" << h << " trial " << trial;
      EXPECT_LT(worst_weight, 1e-3) << w << "x" << h << " trial " << trial;
      EXPECT_LE(validity_flips, 4) << w << "x" << h << " trial " << trial;
      EXPECT_GT(seen, 200) << "the window must see the frame: " << trial;
    }
  }
}

// A smooth ground pattern (grey levels) at ground point g, wavelength about 40 mosaic pixels.
double pattern(const Eigen::Vector2d& g, double lambda) {
  return 128.0 + 50.0 * std::sin(2 * M_PI * g.x() / lambda) * std::cos(2 * M_PI * g.y() / (1.3 * lambda)) +
         20.0 * std::sin(2 * M_PI * (g.x() + g.y()) / (2.1 * lambda));
}

// A frame rendered from the ground pattern through CameraModel::unproject, row y seen from the
// robot at row_pose(y) (a rolling shutter when that changes with y); the mosaic pixels the
// reference warps it to, against the pattern: RMS and worst difference in grey levels.
struct BackWarp {
  int seen = 0;
  double rms = 0, worst = 0;
};

template <typename RowPose>
cv::Mat render_pattern(const Case& c, int w, int h, double lambda, RowPose row_pose) {
  const Extrinsics& e = c.setup.extrinsics;
  cv::Mat frame(h, w, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < h; ++y) {
    const Eigen::Matrix4d T_wc = row_pose(y).matrix3d() * e.T_vc();
    const Eigen::Matrix3d R = T_wc.topLeftCorner<3, 3>();
    const Eigen::Vector3d C = T_wc.topRightCorner<3, 1>();
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2d n = c.setup.camera.unproject({x, y});
      const Eigen::Vector3d d = R * Eigen::Vector3d(n.x(), n.y(), 1.0);
      if (d.z() >= 0) continue;
      const Eigen::Vector3d g = C + (-C.z() / d.z()) * d;
      frame.at<uint8_t>(y, x) = static_cast<uint8_t>(std::lround(pattern(g.head<2>(), lambda)));
    }
  }
  return frame;
}

BackWarp warp_back(const Case& c, const cv::Mat& frame, const WarpParams& prm, double lambda) {
  const Extrinsics& e = c.setup.extrinsics;
  const cv::Mat out = mosaic_warp_reference(frame, prm, c.window.width, c.window.height);
  BackWarp b;
  double sum2 = 0;
  for (int row = 0; row < out.rows; ++row)
    for (int col = 0; col < out.cols; ++col) {
      const cv::Vec2f s = out.at<cv::Vec2f>(row, col);
      if (s[1] <= 0) continue;
      const Eigen::Vector2d g = c.grid.ground(c.window.x + col + 0.5, c.window.y + row + 0.5);
      // Within the range limit of the foot point, or the warp was wrong to use it.
      const Eigen::Vector2d foot = c.pose * Eigen::Vector2d(e.x, e.y);
      EXPECT_LE((g - foot).norm(), c.setup.max_range * (1 + 1e-5) + c.grid.resolution);
      const double err = s[0] - pattern(g, lambda);
      sum2 += err * err;
      b.worst = std::max(b.worst, std::abs(err));
      ++b.seen;
    }
  b.rms = b.seen > 0 ? std::sqrt(sum2 / b.seen) : 0.0;
  return b;
}

TEST(MosaicWarpReference, WarpsTheGroundBackToItself) {
  sim::Random r(7);
  for (int trial = 0; trial < 5; ++trial) {
    const int w = 320, h = 240;
    Case c = random_case(r, w, h);
    const double lambda = 40.0 * c.grid.resolution;
    const cv::Mat frame = render_pattern(c, w, h, lambda, [&](int) { return c.pose; });
    const BackWarp b = warp_back(c, frame, warp_params(c.setup, c.pose, c.grid, c.window), lambda);
    ASSERT_GT(b.seen, 1000) << trial;
    // Rounding to 8 bits (0.29 RMS) and bilinear interpolation of a pattern sampled a few frame
    // pixels per wavelength; a pixel's worth of misplacement would give about 10 RMS.
    EXPECT_LT(b.rms, 1.5) << trial;
    EXPECT_LT(b.worst, 12.0) << trial;
  }
}

// The same with a rolling shutter read out over 30 ms while driving fast (fast_velocity): each
// row rendered from the robot's exact pose when it was read (an arc on SE(2), in double), warped
// back with the three rows' poses. Taken as a global shutter, the same frame comes back several
// pixels off.
TEST(MosaicWarpReference, WarpsARollingShutterFrameBackToTheGround) {
  sim::Random r(11);
  const double readout = 0.03;
  for (int trial = 0; trial < 4; ++trial) {
    const int w = 320, h = 240;
    Case c = random_case(r, w, h);
    const Eigen::Vector3d velocity = fast_velocity(c.setup.extrinsics);
    c.setup.camera.rolling_shutter_readout = readout;
    const double lambda = 40.0 * c.grid.resolution;
    const cv::Mat frame = render_pattern(c, w, h, lambda, [&](int y) {
      return c.pose * SE2::exp(velocity * (readout * y / (h - 1)));
    });
    const BackWarp rolling =
        warp_back(c, frame, warp_params(c.setup, fast_readout_poses(c.setup.extrinsics, c.pose, readout), c.grid, c.window),
                  lambda);
    const BackWarp global = warp_back(c, frame, warp_params(c.setup, c.pose, c.grid, c.window), lambda);
    ASSERT_GT(rolling.seen, 1000) << trial;
    EXPECT_LT(rolling.rms, 1.5) << trial;
    EXPECT_LT(rolling.worst, 12.0) << trial;
    EXPECT_GT(global.rms, 5.0) << trial;
    std::printf("trial %d: RMS %.2f grey levels row by row, %.2f taken as a global shutter\n", trial, rolling.rms,
                global.rms);
  }
}

}  // namespace
}  // namespace planarvo::mosaic
