// End to end: a simulated data set (2 s at 320x240, mixed motion up to 0.8 m/s and 1.5 rad/s,
// noise, gain drift, lens distortion) written to disk, read back with io::Dataset and tracked
// frame by frame through the camera-frame API; the motions against the ground truth.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "core/extrinsics.h"
#include "io/dataset/dataset.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"
#include "track/evaluation.h"
#include "track/tracker.h"

namespace planarvo::track {
namespace {

// A camera on a car (60 degree field of view) driving at up to 3 m/s with turns of at least 6 m
// radius, rendered with 2x2 supersampling: the paper's rear parking camera setting.
sim::Options car_camera(const char* texture, int width, int height, const Extrinsics& e, double seconds) {
  sim::Options so;
  so.texture = test::texture(texture).string();
  so.camera = sim::default_camera(width, height, 60.0);
  so.extrinsics = e;
  so.motion = sim::MotionProfile::Car;
  so.max_speed = 3.0;
  so.min_turn_radius = 6.0;
  so.seconds = seconds;
  so.supersampling = 2;
  return so;
}

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

// A rear parking camera (1.1 m up, 55 degrees from vertical, 60 degree field of view, looking
// back) over fine tiles, a car at up to 3 m/s: the far field is foreshortened, and at the
// coarsest level the grout lines average away (mean squared gradient 0.17, where a flat frame
// of 1 grey level of noise has 0.01). The first frame becomes the keyframe and every frame
// tracks within 0.2 mm of the truth (the tracker used to refuse every frame as "no texture").
TEST(TrackSequence, RearCameraOverFineTilesStartsAndTracks) {
  ocl::Runtime rt;
  const sim::Options so = car_camera("anti_skid_tiles.png", 640, 480, Extrinsics{-1.0, 0.2, 1.1, 0.0, 55.0 * M_PI / 180.0, M_PI}, 0.5);
  const sim::Trajectory traj = sim::generate_trajectory(so);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  Tracker tracker(rt, so.camera, so.extrinsics);
  for (size_t k = 0; k < traj.t.size(); ++k) {
    const cv::Mat f = sim::apply_camera(renderer.render_float(traj.pose[k]), {}, 1.0, 100 + k);
    const FrameResult r = tracker.track(f.data, f.cols, f.rows, f.step, traj.t[k]);
    if (k == 0) {
      EXPECT_EQ(r.status, FrameResult::Status::First) << r.reason;
      continue;
    }
    EXPECT_EQ(r.status, FrameResult::Status::Ok) << k << " " << r.reason;
    const SE2 t = traj.pose[k - 1].inverse() * traj.pose[k];
    EXPECT_LT(std::hypot(r.motion.value.x - t.x, r.motion.value.y - t.y), 0.2e-3) << k;
  }
}

// A rear camera on a car driving along its viewing direction: the overlap with the keyframe stays
// high while the ground's scale in the image changes, so the tracker also makes a new keyframe
// when the scale has changed by more than keyframe_scale_change. Checked against the truth: no
// frame is aligned with a keyframe whose ground it sees more than 12 % larger or smaller (the
// scale from the true motion's homography, core's ground_homography, differentiated
// numerically at the image's centre and corners), and every frame is Ok.
TEST(TrackSequence, APerspectiveViewGetsANewKeyframeWhenTheScaleChanges) {
  ocl::Runtime rt;
  const sim::Options so = car_camera("asphalt_01.png", 320, 240, Extrinsics{-1.0, 0.0, 0.8, 0.0, 35.0 * M_PI / 180.0, M_PI}, 3.0);
  const sim::Trajectory traj = sim::generate_trajectory(so);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  const Eigen::Matrix3d K = so.camera.K();
  // The largest |log linear scale| of the true warp from frame a to frame b.
  auto true_scale_change = [&](size_t a, size_t b) {
    const Eigen::Matrix3d H = ground_homography(K, so.extrinsics, (traj.pose[a].inverse() * traj.pose[b]).matrix3d());
    auto warp = [&](double u, double v) {
      const Eigen::Vector3d q = H * Eigen::Vector3d(u, v, 1.0);
      return Eigen::Vector2d(q.x() / q.z(), q.y() / q.z());
    };
    double worst = 0.0;
    for (double u : {0.0, 159.5, 319.0})
      for (double v : {0.0, 119.5, 239.0}) {
        const double h = 1e-3;
        const Eigen::Vector2d du = (warp(u + h, v) - warp(u - h, v)) / (2 * h);
        const Eigen::Vector2d dv = (warp(u, v + h) - warp(u, v - h)) / (2 * h);
        worst = std::max(worst, std::abs(0.5 * std::log(du.x() * dv.y() - du.y() * dv.x())));
      }
    return worst;
  };
  // With the rule, and without it (to show that the drive needs it): the largest scale change
  // from its keyframe of a frame after which the keyframe was kept, so that the next frame was
  // aligned with it.
  double kept_largest[2] = {0.0, 0.0};
  for (int with_rule = 1; with_rule >= 0; --with_rule) {
    TrackerOptions o;
    if (!with_rule) o.keyframe_scale_change = 100.0;
    Tracker tracker(rt, so.camera, so.extrinsics, o);
    size_t keyframe = 0;
    int keyframes = 0;
    double travelled = 0.0;
    for (size_t k = 0; k < traj.t.size(); ++k) {
      const cv::Mat f = sim::apply_camera(renderer.render_float(traj.pose[k]), {}, 1.0, 300 + k);
      const FrameResult r = tracker.track(f.data, f.cols, f.rows, f.step, traj.t[k]);
      if (k > 0) {
        EXPECT_EQ(r.status, FrameResult::Status::Ok) << k << " " << r.reason;
        const SE2 m = traj.pose[k - 1].inverse() * traj.pose[k];
        travelled += std::hypot(m.x, m.y);
      }
      if (r.keyframe) {
        keyframe = k;
        ++keyframes;
      } else {
        kept_largest[with_rule] = std::max(kept_largest[with_rule], true_scale_change(keyframe, k));
      }
    }
    std::printf("rule %s: %d keyframes over %.2f m; largest scale change of a frame that kept its keyframe %.3f\n",
                with_rule ? "on" : "off", keyframes, travelled, kept_largest[with_rule]);
    EXPECT_GT(travelled, 1.0);
  }
  EXPECT_LT(kept_largest[1], std::log(1.12));
  EXPECT_GT(kept_largest[0], std::log(1.12)) << "the drive should need the rule";
}

// Full resolution from one pixel per 4x4 block (TrackerOptions::select_blocks[0], the C API's
// level0_subsample), joined with the half-resolution level's estimate: every frame of a 640x480
// drive is Ok and within a few micrometres of the truth.
TEST(TrackSequence, FullResolutionFromSubsampledPixels) {
  ocl::Runtime rt;
  sim::Options so;
  so.texture = test::texture("asphalt_01.png").string();
  so.camera = sim::default_camera(640, 480);
  so.seconds = 1.0;
  so.seed = 3;
  so.supersampling = 2;
  const sim::Trajectory traj = sim::generate_trajectory(so);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  TrackerOptions o;
  o.finest_level = 0;
  o.select_blocks[0] = 4;
  Tracker tracker(rt, so.camera, so.extrinsics, o);
  std::vector<SE2> est, truth;
  std::vector<double> dts;
  for (size_t k = 0; k < traj.t.size(); ++k) {
    const cv::Mat f = sim::apply_camera(renderer.render_float(traj.pose[k]), {}, 1.0, 200 + k);
    const FrameResult r = tracker.track(f.data, f.cols, f.rows, f.step, traj.t[k]);
    if (k == 0) continue;
    EXPECT_EQ(r.status, FrameResult::Status::Ok) << k << " " << r.reason;
    EXPECT_GT(r.iterations[0], 0) << "level 0 was aligned";
    est.push_back(r.motion.value);
    truth.push_back(traj.pose[k - 1].inverse() * traj.pose[k]);
    dts.push_back(traj.t[k] - traj.t[k - 1]);
  }
  const MotionAccuracy a = evaluate_motions(est, truth, dts);
  std::printf("%d intervals, %.3f m: RMS %.4f mm, max %.4f mm\n", a.intervals, a.distance, a.rms_translation * 1e3,
              a.max_translation * 1e3);
  EXPECT_LT(a.rms_translation, 0.008e-3);
  EXPECT_LT(a.max_translation, 0.04e-3);
}

// The default at 640x480 (finest_level -1): half resolution on every pixel, then full resolution
// on one pixel in 9 with the half-resolution estimate as a prior. Every frame Ok, level 0
// aligned, and closer to the truth than stopping at half resolution on the same frames.
TEST(TrackSequence, TheDefaultAt640x480FinishesAtFullResolutionOnOnePixelIn9) {
  ocl::Runtime rt;
  sim::Options so;
  so.texture = test::texture("anti_skid_tiles.png").string();
  so.camera = sim::default_camera(640, 480);
  so.seconds = 1.0;
  so.seed = 4;
  so.supersampling = 2;
  const sim::Trajectory traj = sim::generate_trajectory(so);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  TrackerOptions half;
  half.finest_level = 1;
  Tracker def(rt, so.camera, so.extrinsics), stop(rt, so.camera, so.extrinsics, half);
  std::vector<SE2> est_def, est_half, truth;
  std::vector<double> dts;
  for (size_t k = 0; k < traj.t.size(); ++k) {
    const cv::Mat f = sim::apply_camera(renderer.render_float(traj.pose[k]), {}, 1.0, 300 + k);
    const FrameResult r = def.track(f.data, f.cols, f.rows, f.step, traj.t[k]);
    const FrameResult h = stop.track(f.data, f.cols, f.rows, f.step, traj.t[k]);
    if (k == 0) continue;
    EXPECT_EQ(r.status, FrameResult::Status::Ok) << k << " " << r.reason;
    EXPECT_GT(r.iterations[0], 0) << "level 0 was aligned";
    EXPECT_EQ(h.iterations[0], 0) << "finest_level 1 stops at half resolution";
    est_def.push_back(r.motion.value);
    est_half.push_back(h.motion.value);
    truth.push_back(traj.pose[k - 1].inverse() * traj.pose[k]);
    dts.push_back(traj.t[k] - traj.t[k - 1]);
  }
  const MotionAccuracy a = evaluate_motions(est_def, truth, dts), b = evaluate_motions(est_half, truth, dts);
  std::printf("%d intervals, %.3f m: default RMS %.4f mm, max %.4f mm; half resolution RMS %.4f mm, max %.4f mm\n",
              a.intervals, a.distance, a.rms_translation * 1e3, a.max_translation * 1e3, b.rms_translation * 1e3,
              b.max_translation * 1e3);
  EXPECT_LT(a.rms_translation, 0.85 * b.rms_translation);
  EXPECT_LT(a.rms_translation, 0.006e-3);
  EXPECT_LT(a.max_translation, 0.03e-3);
}

// The default's subsampled full resolution on a rear camera (1.1 m up, 55 degrees from vertical)
// over asphalt as the car pulls away: half resolution's estimate is biased there by many of its
// standard deviations, and the prior it gives the subsample is inflated until it agrees with the
// subsample's own data (AlignerOptions::prior_chi2). Against full resolution on every pixel (no
// prior) on the same frames: the default's RMS error within 1.6 times its RMS and its worst frame
// within 2 times; with the prior at full weight (prior_chi2 0) both are about 3 times.
TEST(TrackSequence, RearCameraSubsampleIsNotHeldByTheHalfResolutionBias) {
  ocl::Runtime rt;
  const sim::Options so = car_camera("asphalt_02.png", 640, 480, Extrinsics{-1.0, 0.2, 1.1, 0.0, 55.0 * M_PI / 180.0, M_PI}, 1.5);
  const sim::Trajectory traj = sim::generate_trajectory(so);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  TrackerOptions full, held;
  full.finest_level = 0;
  held.prior_chi2 = 0.0;
  Tracker def(rt, so.camera, so.extrinsics), ref(rt, so.camera, so.extrinsics, full),
      old(rt, so.camera, so.extrinsics, held);
  std::vector<SE2> e_def, e_ref, e_old, truth;
  std::vector<double> dts;
  for (size_t k = 0; k < traj.t.size(); ++k) {
    const cv::Mat f = sim::apply_camera(renderer.render_float(traj.pose[k]), {}, 1.0, 500 + k);
    const FrameResult a = def.track(f.data, f.cols, f.rows, f.step, traj.t[k]);
    const FrameResult b = ref.track(f.data, f.cols, f.rows, f.step, traj.t[k]);
    const FrameResult c = old.track(f.data, f.cols, f.rows, f.step, traj.t[k]);
    if (k == 0) continue;
    EXPECT_EQ(a.status, FrameResult::Status::Ok) << k << " " << a.reason;
    e_def.push_back(a.motion.value);
    e_ref.push_back(b.motion.value);
    e_old.push_back(c.motion.value);
    truth.push_back(traj.pose[k - 1].inverse() * traj.pose[k]);
    dts.push_back(traj.t[k] - traj.t[k - 1]);
  }
  const MotionAccuracy a = evaluate_motions(e_def, truth, dts), b = evaluate_motions(e_ref, truth, dts),
                       c = evaluate_motions(e_old, truth, dts);
  std::printf("RMS / max mm: default %.4f / %.4f, full resolution %.4f / %.4f, prior at full weight %.4f / %.4f\n",
              a.rms_translation * 1e3, a.max_translation * 1e3, b.rms_translation * 1e3, b.max_translation * 1e3,
              c.rms_translation * 1e3, c.max_translation * 1e3);
  EXPECT_LT(a.rms_translation, 1.6 * b.rms_translation);
  EXPECT_LT(a.max_translation, 2.0 * b.max_translation);
}

}  // namespace
}  // namespace planarvo::track
