// End to end: a rolling-shutter camera (issue 23). A drive rendered row by row from the poses the
// rows are read at (sim::render_frame with readout_time), tracked frame by frame through the
// camera-frame API, the tracker told the camera's readout (CameraModel::rolling_shutter_readout)
// and not told it; the motions against the simulator's ground truth.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"
#include "track/evaluation.h"
#include "track/tracker.h"

namespace planarvo::track {
namespace {

struct Drive {
  sim::Options so;
  sim::Trajectory traj;
  std::vector<cv::Mat> frames;
};

Drive render(ocl::Runtime& rt, int configuration, double readout, double exposure_time = 0.0) {
  Drive d;
  d.so.texture = test::texture("brick_floor.png").string();
  d.so.camera = sim::default_camera(640, 480);
  d.so.camera.rolling_shutter_readout = readout;
  d.so.camera.exposure_time = exposure_time;
  d.so.readout_time = readout;
  d.so.exposure_time = exposure_time;
  d.so.extrinsics = sim::paper_configuration(configuration);
  d.so.seconds = 2.5;
  d.so.seed = 7;
  d.so.supersampling = 2;
  d.traj = sim::generate_trajectory(d.so);
  const std::vector<sim::Exposure> exposure = sim::exposure_series(d.so, d.traj.t);
  sim::Renderer renderer(rt, cv::imread(d.so.texture, cv::IMREAD_GRAYSCALE), d.so);
  for (size_t k = 0; k < d.traj.t.size(); ++k)
    d.frames.push_back(sim::apply_camera(sim::render_frame(renderer, d.so, d.traj, k), exposure[k], d.so.pixel_noise,
                                         sim::derive_seed(d.so.seed, 1000 + k)));
  return d;
}

struct Tracked {
  MotionAccuracy accuracy;
  double max_error = 0;  // metres
  int lost = 0;
};

// Frames [first, end) (end 0: all); told_exposure < 0: the camera's.
Tracked track_drive(ocl::Runtime& rt, const Drive& d, double told_readout, size_t first = 0, size_t end = 0,
                    double told_exposure = -1.0) {
  CameraModel camera = d.so.camera;
  camera.rolling_shutter_readout = told_readout;
  if (told_exposure >= 0.0) camera.exposure_time = told_exposure;
  Tracker tracker(rt, camera, d.so.extrinsics);
  Tracked t;
  std::vector<SE2> est, truth;
  std::vector<double> dts;
  for (size_t k = first; k < (end > 0 ? end : d.frames.size()); ++k) {
    const cv::Mat& f = d.frames[k];
    const FrameResult r = tracker.track(f.data, f.cols, f.rows, f.step, d.traj.t[k]);
    if (k == first) continue;
    const SE2 m = d.traj.pose[k - 1].inverse() * d.traj.pose[k];
    t.max_error = std::max(t.max_error, std::hypot(r.motion.value.x - m.x, r.motion.value.y - m.y));
    t.lost += r.status == FrameResult::Status::Lost;
    est.push_back(r.motion.value);
    truth.push_back(m);
    dts.push_back(d.traj.t[k] - d.traj.t[k - 1]);
  }
  t.accuracy = evaluate_motions(est, truth, dts);
  return t;
}

// A 25 ms readout on the default camera (configuration 1) and on the yawed, tilted configuration
// 2, at up to 0.8 m/s and 1.5 rad/s: told the readout, the tracker is as the issue asks (0 Lost,
// slopes 1 +- 0.002, no frame over 0.2 mm); not told, the same drive is several times worse (at
// 0.8 m/s a 25 ms readout shears the image by 20 mm over its height).
TEST(RollingShutter, TrackerToldTheReadoutTakesTheShearOut) {
  ocl::Runtime rt;
  for (int configuration : {1, 2}) {
    SCOPED_TRACE("configuration " + std::to_string(configuration));
    const Drive d = render(rt, configuration, 0.025);
    const Tracked told = track_drive(rt, d, 0.025);
    const Tracked not_told = track_drive(rt, d, 0.0);
    EXPECT_EQ(told.lost, 0);
    EXPECT_NEAR(told.accuracy.slope_linear, 1.0, 0.002);
    EXPECT_NEAR(told.accuracy.slope_angular, 1.0, 0.002);
    EXPECT_LT(told.max_error, 0.2e-3);
    EXPECT_LT(5.0 * told.accuracy.rms_translation, not_told.accuracy.rms_translation);
    EXPECT_GT(not_told.max_error, 3.0 * told.max_error);
    RecordProperty("rms_told_mm_" + std::to_string(configuration), std::to_string(told.accuracy.rms_translation * 1e3));
    RecordProperty("rms_not_told_mm_" + std::to_string(configuration),
                   std::to_string(not_told.accuracy.rms_translation * 1e3));
  }
}

// A 4 ms exposure (global shutter): each frame is the blurred image of 2 ms before its stamp,
// so, not told, every motion is off by the velocity's change over those 2 ms (the drive
// accelerates). Told (CameraModel::exposure_time), the tracker takes each frame back to its stamp:
// within 2x of the same drive's sharp frames' RMS, and several times better than not told.
TEST(RollingShutter, TrackerToldTheExposureTakesItsTimeOut) {
  ocl::Runtime rt;
  const Drive sharp = render(rt, 1, 0.0);
  const Drive blurred = render(rt, 1, 0.0, 0.004);
  const Tracked reference = track_drive(rt, sharp, 0.0);
  const Tracked told = track_drive(rt, blurred, 0.0);
  const Tracked not_told = track_drive(rt, blurred, 0.0, 0, 0, 0.0);
  EXPECT_EQ(told.lost, 0);
  EXPECT_NEAR(told.accuracy.slope_linear, 1.0, 0.002);
  EXPECT_NEAR(told.accuracy.slope_angular, 1.0, 0.002);
  EXPECT_LT(told.max_error, 0.2e-3);
  EXPECT_LT(told.accuracy.rms_translation, 2.0 * reference.accuracy.rms_translation);
  EXPECT_LT(3.0 * told.accuracy.rms_translation, not_told.accuracy.rms_translation);
  RecordProperty("rms_sharp_mm", std::to_string(reference.accuracy.rms_translation * 1e3));
  RecordProperty("rms_told_mm", std::to_string(told.accuracy.rms_translation * 1e3));
  RecordProperty("rms_not_told_mm", std::to_string(not_told.accuracy.rms_translation * 1e3));
}

// Tracking that starts (or restarts after a Lost frame) while the robot moves fast: the first
// keyframe is undistorted before any twist is measured, then again with the first frame's. Its
// twist is then the measured velocity itself (both frames carried the same shear); the model for
// a keyframe already right (readout_twist.h) would give it 1/(1 + readout/(2 dt)) of it, and at
// 0.6 m/s every later frame was Lost ("misaligned").
TEST(RollingShutter, TrackingThatStartsAtSpeed) {
  ocl::Runtime rt;
  const Drive d = render(rt, 1, 0.025);
  // The fastest frame of the drive's second half, and 15 frames from there.
  size_t first = d.traj.t.size() / 2;
  double fastest = 0;
  for (size_t k = first; k + 16 < d.traj.t.size(); ++k) {
    const SE2 m = d.traj.pose[k].inverse() * d.traj.pose[k + 1];
    if (const double v = std::hypot(m.x, m.y); v > fastest) {
      fastest = v;
      first = k;
    }
  }
  ASSERT_GT(fastest / (d.traj.t[1] - d.traj.t[0]), 0.4);  // m/s: the shear is 10 mm over the image
  const Tracked told = track_drive(rt, d, 0.025, first, first + 16);
  EXPECT_EQ(told.lost, 0);
  EXPECT_LT(told.max_error, 0.5e-3);  // measured 0.27 mm: the first frames' twist is the mean velocity
  RecordProperty("speed_m_s", std::to_string(fastest / (d.traj.t[1] - d.traj.t[0])));
  RecordProperty("max_error_mm", std::to_string(told.max_error * 1e3));
}

}  // namespace
}  // namespace planarvo::track
