// End to end: the camera's own light (issue 23). Drives rendered with a lamp's falloff, its
// reflection on a glossy floor and the robot's shadow (sim::camera_lighting), tracked frame by
// frame through the camera-frame API with the photometric model on (the default) and off; the
// motions against the simulator's ground truth.
#include <algorithm>
#include <cmath>
#include <cstdio>
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

Drive render(ocl::Runtime& rt, const char* texture, double lamp, double reflection, double shadow) {
  Drive d;
  d.so.texture = test::texture(texture).string();
  d.so.camera = sim::default_camera(640, 480);
  d.so.seconds = 3.0;
  d.so.seed = 3;
  d.so.supersampling = 2;
  d.so.lamp_falloff = lamp;
  d.so.reflection = reflection;
  d.so.shadow = shadow;
  d.traj = sim::generate_trajectory(d.so);
  const std::vector<sim::Exposure> exposure = sim::exposure_series(d.so, d.traj.t);
  const sim::Lighting lighting = sim::camera_lighting(d.so);
  sim::Renderer renderer(rt, cv::imread(d.so.texture, cv::IMREAD_GRAYSCALE), d.so);
  for (size_t k = 0; k < d.traj.t.size(); ++k) {
    cv::Mat clean = sim::render_frame(renderer, d.so, d.traj, k);
    sim::apply_lighting(lighting, clean);
    d.frames.push_back(sim::apply_camera(clean, exposure[k], d.so.pixel_noise, sim::derive_seed(d.so.seed, 1000 + k)));
  }
  return d;
}

struct Tracked {
  std::vector<FrameResult> results;
  std::vector<double> error;  // per frame from the second: |estimated - true| translation, metres
  MotionAccuracy accuracy;
  int lost = 0, ok_but_wrong = 0;
};

Tracked track_drive(ocl::Runtime& rt, const Drive& d, bool photometric) {
  TrackerOptions o;
  o.photometric.enabled = photometric;
  Tracker tracker(rt, d.so.camera, d.so.extrinsics, o);
  Tracked t;
  std::vector<SE2> est, truth;
  std::vector<double> dts;
  for (size_t k = 0; k < d.frames.size(); ++k) {
    const cv::Mat& f = d.frames[k];
    const FrameResult r = tracker.track(f.data, f.cols, f.rows, f.step, d.traj.t[k]);
    t.results.push_back(r);
    if (k == 0) continue;
    const SE2 m = d.traj.pose[k - 1].inverse() * d.traj.pose[k];
    const double e = std::hypot(r.motion.value.x - m.x, r.motion.value.y - m.y);
    t.error.push_back(e);
    t.lost += r.status == FrameResult::Status::Lost;
    t.ok_but_wrong += r.status == FrameResult::Status::Ok && e > 1e-3;
    est.push_back(r.motion.value);
    truth.push_back(m);
    dts.push_back(d.traj.t[k] - d.traj.t[k - 1]);
  }
  t.accuracy = evaluate_motions(est, truth, dts);
  return t;
}

// Without the model, a lamp and its reflection hold the alignment at "no motion"; the honest
// status reports those frames Lost rather than ok. With the model the drive is tracked.
TEST(CameraLight, LampAndReflectionAreTakenOutAndHeldFramesAreNotOk) {
  ocl::Runtime rt;
  const Drive d = render(rt, "asphalt_01.png", 0.8, 150.0, 0.0);
  const Tracked off = track_drive(rt, d, false);
  const Tracked on = track_drive(rt, d, true);
  double worst_late = 0.0;
  for (size_t k = 45; k < on.error.size(); ++k) worst_late = std::max(worst_late, on.error[k]);
  std::printf("off: lost %d, ok but > 1 mm %d, slopes %.5f %.5f; on: lost %d, ok but > 1 mm %d, slopes %.5f %.5f, "
              "worst after 1.5 s %.4f mm\n", off.lost, off.ok_but_wrong, off.accuracy.slope_linear,
              off.accuracy.slope_angular, on.lost, on.ok_but_wrong, on.accuracy.slope_linear,
              on.accuracy.slope_angular, worst_late * 1e3);
  // Off: the light holds most frames; the honest status reports them Lost (the motion a
  // prediction) rather than ok. It misses a few (4 of 90 measured: held frames whose floor
  // texture is faint against the light's own gradients; src/track/README.md).
  EXPECT_GT(off.lost, static_cast<int>(d.frames.size()) / 3);
  EXPECT_LE(off.ok_but_wrong, 6);
  // On: tracked, a few frames lost at the start while the model is learnt (4 measured).
  EXPECT_LE(on.lost, 8);
  EXPECT_LE(on.ok_but_wrong, 3);
  EXPECT_NEAR(on.accuracy.slope_linear, 1.0, 0.01);
  EXPECT_NEAR(on.accuracy.slope_angular, 1.0, 0.01);
  // After the first 1.5 s every frame is within 0.2 mm.
  EXPECT_LT(worst_late, 2e-4);
}

// An evenly lit camera: the model stays the identity, so tracking is bit for bit what it is
// without the model.
TEST(CameraLight, EvenLightTracksExactlyAsWithoutTheModel) {
  ocl::Runtime rt;
  const Drive d = render(rt, "brick_floor.png", 0.0, 0.0, 0.0);
  const Tracked off = track_drive(rt, d, false);
  const Tracked on = track_drive(rt, d, true);
  ASSERT_EQ(on.results.size(), off.results.size());
  for (size_t k = 0; k < on.results.size(); ++k) {
    EXPECT_EQ(on.results[k].status, off.results[k].status) << "frame " << k;
    EXPECT_EQ(on.results[k].motion.value.x, off.results[k].motion.value.x) << "frame " << k;
    EXPECT_EQ(on.results[k].motion.value.y, off.results[k].motion.value.y) << "frame " << k;
    EXPECT_EQ(on.results[k].motion.value.theta, off.results[k].motion.value.theta) << "frame " << k;
  }
  EXPECT_EQ(on.lost, 0);
}

}  // namespace
}  // namespace planarvo::track
