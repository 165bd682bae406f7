// The rolling shutter's readout time estimated from a drive (calib/readout_estimate.h, issue 23)
// against the simulator's: a camera read out over 20 ms and the same drive through a global
// shutter, rendered row by row from the poses the rows are read at.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "calib/readout_estimate.h"
#include "common/test_util.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"

namespace planarvo::calib {
namespace {

struct Drive {
  sim::Options so;
  std::vector<cv::Mat> frames;
  std::vector<double> stamps;
};

Drive render(ocl::Runtime& rt, double readout) {
  Drive d;
  d.so.texture = test::texture("asphalt_01.png").string();
  d.so.camera = sim::default_camera(320, 240);
  d.so.readout_time = readout;
  d.so.seconds = 5.0;
  d.so.seed = 11;
  d.so.supersampling = 2;
  const sim::Trajectory traj = sim::generate_trajectory(d.so);
  const std::vector<sim::Exposure> exposure = sim::exposure_series(d.so, traj.t);
  sim::Renderer renderer(rt, cv::imread(d.so.texture, cv::IMREAD_GRAYSCALE), d.so);
  for (size_t k = 0; k < traj.t.size(); ++k) {
    d.frames.push_back(sim::apply_camera(sim::render_frame(renderer, d.so, traj, k), exposure[k], d.so.pixel_noise,
                                         sim::derive_seed(d.so.seed, 1000 + k)));
    d.stamps.push_back(traj.t[k]);
  }
  return d;
}

// The calibration's tracking frame: the camera's true tilt at height 1. The curve searched goes
// to the test's XML output ("readout_ms:mean_variance ...").
ReadoutEstimate estimate(ocl::Runtime& rt, const Drive& d) {
  const Extrinsics& e = d.so.extrinsics;
  const ReadoutEstimate r =
      estimate_readout(rt, d.so.camera, Extrinsics{0.0, 0.0, 1.0, e.roll, e.pitch, 0.0}, d.frames, d.stamps);
  std::string curve;
  for (const auto& [readout, cost] : r.curve) curve += std::to_string(readout * 1e3) + ":" + std::to_string(cost) + " ";
  ::testing::Test::RecordProperty("curve", curve);
  return r;
}

TEST(ReadoutEstimate, FindsARollingShuttersReadout) {
  ocl::Runtime rt;
  const Drive d = render(rt, 0.020);
  const ReadoutEstimate r = estimate(rt, d);
  ASSERT_TRUE(r.ok) << r.reason;
  RecordProperty("estimate_ms", std::to_string(r.estimate * 1e3));
  RecordProperty("sigma_ms", std::to_string(r.sigma * 1e3));
  EXPECT_NEAR(r.estimate, 0.020, 0.0015);  // measured 20.57 +- 0.32 ms
  EXPECT_GT(r.sigma, 0.0);
  EXPECT_LT(std::abs(r.estimate - 0.020), 4.0 * r.sigma);
  EXPECT_EQ(r.readout, r.estimate);  // far from 0: used as it is
  // The lowest point of the curve it searched is a candidate next to the truth.
  double best = 1e9, best_r = -1;
  for (const auto& [readout, cost] : r.curve)
    if (cost < best) {
      best = cost;
      best_r = readout;
    }
  EXPECT_LE(std::abs(best_r - 0.020), r.max_readout / 8);
}

TEST(ReadoutEstimate, AGlobalShutterReadsAsAFewMilliseconds) {
  ocl::Runtime rt;
  const Drive d = render(rt, 0.0);
  const ReadoutEstimate r = estimate(rt, d);
  ASSERT_TRUE(r.ok) << r.reason;
  RecordProperty("estimate_ms", std::to_string(r.estimate * 1e3));
  RecordProperty("sigma_ms", std::to_string(r.sigma * 1e3));
  // Not 0 at this size: measured 2.7 +- 0.3 ms, the residuals smallest at about 4 ms for reasons
  // not found (at 640x480 a global shutter reads 0.0 +- 0.5 ms; calib/README.md). Far from any
  // real rolling shutter's 10-35 ms, and why the estimate is not on by default.
  EXPECT_LT(r.estimate, 0.005);
}

TEST(ReadoutEstimate, AStillCameraSaysSo) {
  ocl::Runtime rt;
  Drive d = render(rt, 0.020);
  // The first frame over and over: nothing shears it.
  for (cv::Mat& f : d.frames) f = d.frames[0];
  const ReadoutEstimate r = estimate(rt, d);
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.reason.empty());
}

}  // namespace
}  // namespace planarvo::calib
