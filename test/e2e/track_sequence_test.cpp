// End to end: a simulated data set (2 s at 320x240, mixed motion up to 0.8 m/s and 1.5 rad/s,
// noise, gain drift, lens distortion) written to disk, read back with io::Dataset and tracked
// frame by frame through the camera-frame API; the motions against the ground truth.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "common/test_util.h"
#include "io/dataset.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"
#include "track/evaluation.h"
#include "track/tracker.h"

namespace planarvo::track {
namespace {

TEST(TrackSequence, SimulatedDataSetIsTrackedAccurately) {
  test::ScratchDir dir;
  ocl::Runtime rt;
  sim::Options so;
  so.texture = test::texture("aerial_ground_rock.png").string();
  so.camera = sim::default_camera(320, 240);
  so.seconds = 2.0;
  so.seed = 5;
  so.supersampling = 2;
  sim::simulate(rt, so, dir.path().string());

  io::Dataset ds(dir.path().string());
  ASSERT_TRUE(ds.has_groundtruth());
  Tracker tracker(rt, ds.camera(), ds.extrinsics_gt()->value);
  std::vector<SE2> est, truth;
  std::vector<double> dts;
  int ok = 0;
  for (int64_t i = 0; i < ds.frame_count(); ++i) {
    const cv::Mat f = ds.frame(i);
    const FrameResult r = tracker.track(f.data, f.cols, f.rows, f.step, ds.timestamp(i));
    if (i == 0) {
      EXPECT_EQ(r.status, FrameResult::Status::First);
      continue;
    }
    ok += r.status == FrameResult::Status::Ok;
    est.push_back(r.motion.value);
    truth.push_back(ds.groundtruth_at(i - 1)->inverse() * *ds.groundtruth_at(i));
    dts.push_back(ds.timestamp(i) - ds.timestamp(i - 1));
  }
  const MotionAccuracy a = evaluate_motions(est, truth, dts);
  std::printf("%d intervals, %d ok, %.3f m: slopes %.5f %.5f, RMS %.4f mm, max %.4f mm, drift %.4f %%\n",
              a.intervals, ok, a.distance, a.slope_linear, a.slope_angular, a.rms_translation * 1e3,
              a.max_translation * 1e3, a.endpoint_drift * 100);
  EXPECT_EQ(ok, a.intervals);
  EXPECT_NEAR(a.slope_linear, 1.0, 0.005);
  EXPECT_NEAR(a.slope_angular, 1.0, 0.005);
  EXPECT_LT(a.rms_translation, 0.05e-3);
  EXPECT_EQ(a.gross_errors, 0);
  EXPECT_LT(a.endpoint_drift, 0.01);
  // The accumulated pose is the composition of the reported motions.
  SE2 composed;
  for (const SE2& m : est) composed = composed * m;
  EXPECT_NEAR(tracker.pose().x, composed.x, 1e-12);
  EXPECT_NEAR(tracker.pose().theta, composed.theta, 1e-12);
}

}  // namespace
}  // namespace planarvo::track
