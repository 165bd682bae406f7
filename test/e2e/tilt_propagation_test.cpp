// End to end: the tracker's tilt Jacobians (TrackerOptions::tilt_jacobian, for
// calib/tilt_propagation.h) against the tracker itself. A drive rendered by the simulator with a
// rolled camera is tracked in stage 2's frame with the true tilt (its Jacobians made) and with the
// tilt off by delta: each motion moved along its Jacobian must predict the second run's (a
// derivative against a difference). And the change must be far above the tracker's noise, or the
// test would say nothing.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "calib/extrinsics_estimate.h"
#include "calib/tilt_propagation.h"
#include "common/test_util.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"
#include "track/tracker.h"

namespace planarvo::calib {
namespace {

TEST(TiltPropagation, TheTrackersTiltJacobiansPredictMotionsTrackedWithATiltError) {
  ocl::Runtime rt;
  sim::Options so;
  so.texture = test::texture("asphalt_01.png").string();
  so.camera = sim::default_camera(640, 480);
  so.extrinsics = sim::paper_configuration(2);  // roll 29.8, pitch -4.6 deg
  so.seconds = 2.0;
  so.seed = 4;
  so.supersampling = 2;
  const sim::Trajectory traj = sim::generate_trajectory(so);
  const std::vector<sim::Exposure> exposure = sim::exposure_series(so, traj.t);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  std::vector<cv::Mat> frames;
  for (size_t k = 0; k < traj.t.size(); ++k)
    frames.push_back(sim::apply_camera(sim::render_frame(renderer, so, traj, k), exposure[k], so.pixel_noise,
                                       sim::derive_seed(so.seed, 1000 + k)));
  const double roll = so.extrinsics.roll, pitch = so.extrinsics.pitch;
  std::vector<Eigen::Matrix<double, 3, 2>> jacobians;
  auto track = [&](const Eigen::Vector2d& delta) {
    track::TrackerOptions o;
    o.tilt_jacobian = delta.isZero();
    track::Tracker tracker(rt, so.camera, stage2_extrinsics(roll + delta.x(), pitch + delta.y()), o);
    std::vector<SE2> motions;
    for (size_t k = 0; k < frames.size(); ++k) {
      const track::FrameResult r = tracker.track(frames[k].data, frames[k].cols, frames[k].rows, frames[k].step, traj.t[k]);
      if (k == 0) continue;
      EXPECT_EQ(r.status, track::FrameResult::Status::Ok) << "frame " << k;
      motions.push_back(r.motion.value);
      if (o.tilt_jacobian) jacobians.push_back(r.motion_tilt_jacobian);
    }
    return motions;
  };
  const std::vector<SE2> base = track(Eigen::Vector2d::Zero());
  ASSERT_EQ(jacobians.size(), base.size());
  for (const Eigen::Vector2d& delta : {Eigen::Vector2d(0.001, 0.0), Eigen::Vector2d(0.0, -0.001)}) {
    SCOPED_TRACE("delta " + std::to_string(delta.x()) + " " + std::to_string(delta.y()));
    const std::vector<SE2> off = track(delta);
    ASSERT_EQ(off.size(), base.size());
    // What yaw sees: the turn of the motions' directions and their rotation (radians); and the
    // worst single motion's change and miss (units of the camera height).
    double length2 = 0, turn = 0, turn_predicted = 0, theta = 0, theta_predicted = 0, worst_change = 0, worst_miss = 0;
    for (size_t i = 0; i < off.size(); ++i) {
      const SE2 p = base[i] * SE2::exp(jacobians[i] * delta);
      const SE2& a = base[i];
      length2 += a.x * a.x + a.y * a.y;
      turn += a.x * (off[i].y - a.y) - a.y * (off[i].x - a.x);
      turn_predicted += a.x * (p.y - a.y) - a.y * (p.x - a.x);
      theta += off[i].theta - a.theta;
      theta_predicted += p.theta - a.theta;
      worst_change = std::max(worst_change, std::hypot(off[i].x - a.x, off[i].y - a.y));
      worst_miss = std::max(worst_miss, std::hypot(off[i].x - p.x, off[i].y - p.y));
    }
    turn /= length2;  // the mean turn of the motions' directions, weighted by their length squared
    turn_predicted /= length2;
    // Measured: roll 10 % off in the turn, pitch 2 %, both 1-2 % in the rotation; the worst
    // motion's miss a tenth of its change or less.
    EXPECT_NEAR(turn_predicted, turn, 0.2 * std::abs(turn));
    EXPECT_NEAR(theta_predicted, theta, 0.1 * std::abs(theta));
    EXPECT_GT(worst_change, 5.0 * worst_miss);
    RecordProperty("turn_" + std::to_string(delta.x()), std::to_string(turn));
    RecordProperty("turn_predicted_" + std::to_string(delta.x()), std::to_string(turn_predicted));
    RecordProperty("theta_" + std::to_string(delta.x()), std::to_string(theta));
    RecordProperty("theta_predicted_" + std::to_string(delta.x()), std::to_string(theta_predicted));
    std::printf("turn %.4g predicted %.4g, theta %.4g predicted %.4g, worst change %.3g miss %.3g\n", turn,
                turn_predicted, theta, theta_predicted, worst_change, worst_miss);
  }
}

}  // namespace
}  // namespace planarvo::calib
