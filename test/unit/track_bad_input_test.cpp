// The tracker on bad input: black, saturated and textureless frames, a frame of another size,
// gaps and bad timestamps. Each gives Lost or Degraded with a reason, a finite motion and pose,
// and tracking recovers on the next good frame; the pose stays close to the truth where the
// good frames allow it.
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "core/error.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"
#include "track/tracker.h"
#include "unit/track_test_pyramid.h"

namespace planarvo::track {
namespace {

using Status = FrameResult::Status;

class TrackBadInput : public ::testing::Test {
 protected:
  TrackBadInput() {
    options_.texture = test::texture("asphalt_01.png").string();
    options_.camera = sim::default_camera(320, 240);
    options_.camera.k1 = options_.camera.k2 = 0.0;
    renderer_ = std::make_unique<sim::Renderer>(rt_, cv::imread(options_.texture, cv::IMREAD_GRAYSCALE), options_);
    tracker_ = std::make_unique<Tracker>(rt_, options_.camera, options_.extrinsics);
  }

  // Constant velocity 0.3 m/s and 0.6 rad/s: frame k at time k / 30 s.
  static SE2 truth(double t) { return SE2::exp(Eigen::Vector3d(0.3 * t, 0.0, 0.6 * t)); }

  Pyramid good(double t, uint64_t seed = 7) {
    const cv::Mat u8 = sim::apply_camera(renderer_->render_float(truth(t)), {}, 1.0, seed + static_cast<uint64_t>(t * 1000));
    return test::test_upload(rt_, test::test_pyramid(u8, nullptr, 4));
  }
  Pyramid flat(double value, double noise, int w = 320, int h = 240) {
    cv::Mat f(h, w, CV_32FC1, cv::Scalar(value));
    const cv::Mat u8 = sim::apply_camera(f, {}, noise, 3);
    return test::test_upload(rt_, test::test_pyramid(u8, nullptr, 4));
  }

  FrameResult track(const Pyramid& p, double t) {
    const FrameResult r = tracker_->track(p, t);
    EXPECT_TRUE(std::isfinite(r.motion.value.x) && std::isfinite(r.motion.value.y) && std::isfinite(r.motion.value.theta));
    EXPECT_TRUE(r.motion.covariance.allFinite());
    EXPECT_TRUE(std::isfinite(tracker_->pose().x) && std::isfinite(tracker_->pose().theta));
    if (r.status == Status::Lost || r.status == Status::Degraded) {
      EXPECT_STRNE(r.reason, "");
    }
    return r;
  }
  // Distance between the tracker's pose and the truth at t (the first frame at t0).
  double pose_error_mm(double t0, double t) const {
    const SE2 rel = truth(t0).inverse() * truth(t);
    return 1e3 * std::hypot(tracker_->pose().x - rel.x, tracker_->pose().y - rel.y);
  }

  ocl::Runtime rt_;
  sim::Options options_;
  std::unique_ptr<sim::Renderer> renderer_;
  std::unique_ptr<Tracker> tracker_;
};

constexpr double dt = 1.0 / 30;

// The good frame after a Lost one: tracked against the keyframe, Degraded because its motion
// starts from the Lost frame's predicted pose, with a covariance that says so (1 m^2, 1 rad^2).
void expect_after_lost(const FrameResult& r) {
  EXPECT_STREQ(status_name(r.status), status_name(FrameResult::Status::Degraded)) << r.reason;
  EXPECT_GE(r.motion.covariance(0, 0), 0.5);
  EXPECT_GE(r.motion.covariance(2, 2), 0.5);
}

#define EXPECT_STATUS(result, expected)                                              \
  do {                                                                               \
    const FrameResult r_ = (result);                                                 \
    EXPECT_STREQ(status_name(r_.status), status_name(Status::expected)) << r_.reason; \
  } while (0)

TEST_F(TrackBadInput, BlackAndSaturatedFramesAreLostThenTrackingResumes) {
  EXPECT_STATUS(track(good(0), 0), First);
  for (int k = 1; k <= 3; ++k) EXPECT_STATUS(track(good(k * dt), k * dt), Ok);
  // Black: lost, the motion is the constant-velocity prediction, the keyframe is kept.
  const FrameResult black = track(flat(0, 0), 4 * dt);
  EXPECT_STATUS(black, Lost);
  EXPECT_FALSE(black.keyframe);
  const SE2 step = truth(3 * dt).inverse() * truth(4 * dt);
  EXPECT_NEAR(black.motion.value.x, step.x, 1e-4);
  EXPECT_NEAR(black.motion.value.theta, step.theta, 1e-3);
  // The next good frame is tracked against the keyframe: the pose is right again. Its motion
  // starts from the black frame's predicted pose, so it is Degraded, with that motion's
  // covariance; the frames after it are Ok.
  expect_after_lost(track(good(5 * dt), 5 * dt));
  EXPECT_LT(pose_error_mm(0, 5 * dt), 0.05);
  // Saturated: the same.
  const FrameResult white = track(flat(255, 0), 6 * dt);
  EXPECT_STATUS(white, Lost);
  expect_after_lost(track(good(7 * dt), 7 * dt));
  for (int k = 8; k <= 9; ++k) EXPECT_STATUS(track(good(k * dt), k * dt), Ok);
  EXPECT_LT(pose_error_mm(0, 9 * dt), 0.05);
}

TEST_F(TrackBadInput, TexturelessFrameIsLost) {
  track(good(0), 0);
  track(good(dt), dt);
  const FrameResult r = track(flat(110, 1.0), 2 * dt);
  EXPECT_STATUS(r, Lost);
  expect_after_lost(track(good(3 * dt), 3 * dt));
  EXPECT_LT(pose_error_mm(0, 3 * dt), 0.05);
}

TEST_F(TrackBadInput, BadFirstFramesDoNotBecomeTheKeyframe) {
  EXPECT_STATUS(track(flat(0, 0), 0), Lost);
  EXPECT_STATUS(track(flat(128, 1.0), dt), Lost);
  EXPECT_STATUS(track(good(2 * dt), 2 * dt), First);
  EXPECT_STATUS(track(good(3 * dt), 3 * dt), Ok);
}

TEST_F(TrackBadInput, FrameOfAnotherSizeIsLost) {
  track(good(0), 0);
  track(good(dt), dt);
  const FrameResult r = track(flat(100, 5.0, 160, 120), 2 * dt);
  EXPECT_STATUS(r, Lost);
  EXPECT_FALSE(r.keyframe);
  expect_after_lost(track(good(3 * dt), 3 * dt));
  EXPECT_LT(pose_error_mm(0, 3 * dt), 0.05);
}

TEST_F(TrackBadInput, ShortGapIsDegradedButTracked) {
  track(good(0), 0);
  track(good(dt), dt);
  track(good(2 * dt), 2 * dt);
  // Five frames missing: 50 mm and 0.1 rad in one interval, predicted from the velocity.
  const FrameResult r = track(good(8 * dt), 8 * dt);
  EXPECT_STATUS(r, Degraded);
  const SE2 step = truth(2 * dt).inverse() * truth(8 * dt);
  EXPECT_LT(1e3 * std::hypot(r.motion.value.x - step.x, r.motion.value.y - step.y), 0.05);
  EXPECT_STATUS(track(good(9 * dt), 9 * dt), Ok);
  EXPECT_LT(pose_error_mm(0, 9 * dt), 0.05);
}

TEST_F(TrackBadInput, LongGapIsLostThenTheFrameIsTheNewKeyframe) {
  track(good(0), 0);
  track(good(dt), dt);
  // Three seconds later the robot is a metre away: nothing overlaps. Lost, zero motion (no
  // prediction over so long), and the textured frame becomes the keyframe.
  const FrameResult r = track(good(3.0), 3.0);
  EXPECT_STATUS(r, Lost);
  EXPECT_TRUE(r.keyframe);
  EXPECT_EQ(r.motion.value.x, 0.0);
  EXPECT_EQ(r.motion.value.theta, 0.0);
  const FrameResult next = track(good(3.0 + dt), 3.0 + dt);
  EXPECT_STATUS(next, Ok);
  const SE2 step = truth(3.0).inverse() * truth(3.0 + dt);
  EXPECT_LT(1e3 * std::hypot(next.motion.value.x - step.x, next.motion.value.y - step.y), 0.02);
}

TEST_F(TrackBadInput, BadTimestampsAreDegradedNotNaN) {
  track(good(0), 0);
  track(good(dt), dt);
  // Not finite, repeated, backwards: the frame is tracked with the usual interval assumed.
  for (const double t : {std::nan(""), dt, 0.5 * dt}) {
    const FrameResult r = track(good(2 * dt), t);
    EXPECT_STATUS(r, Degraded);
    EXPECT_STREQ(r.reason, "timestamp not increasing");
  }
  EXPECT_STATUS(track(good(3 * dt), 3 * dt), Ok);
  EXPECT_LT(pose_error_mm(0, 3 * dt), 0.05);
}

TEST_F(TrackBadInput, CameraFrameApi) {
  // The same through track(gray, ...): the image pipeline makes the pyramids. A frame of
  // another size is Lost, not an exception; a null image or a short stride is a caller error.
  auto frame = [&](double t) {
    return sim::apply_camera(renderer_->render_float(truth(t)), {}, 1.0, 11 + static_cast<uint64_t>(t * 1000));
  };
  Tracker tr(rt_, options_.camera, options_.extrinsics);
  cv::Mat f = frame(0);
  EXPECT_STATUS(tr.track(f.data, f.cols, f.rows, f.step, 0.0), First);
  f = frame(dt);
  const FrameResult r1 = tr.track(f.data, f.cols, f.rows, f.step, dt);
  EXPECT_STATUS(r1, Ok);
  EXPECT_GT(r1.pipeline_ms, 0.0);
  EXPECT_GE(r1.ms, r1.pipeline_ms);
  cv::Mat small(120, 160, CV_8UC1, cv::Scalar(90));
  cv::randu(small, 0, 255);
  EXPECT_STATUS(tr.track(small.data, small.cols, small.rows, small.step, 2 * dt), Lost);
  // A frame inside a larger buffer (stride > width).
  f = frame(3 * dt);
  cv::Mat padded(f.rows, f.cols + 13, CV_8UC1, cv::Scalar(0));
  f.copyTo(padded(cv::Rect(0, 0, f.cols, f.rows)));
  const FrameResult r3 = tr.track(padded.data, f.cols, f.rows, padded.step, 3 * dt);
  expect_after_lost(r3);
  const SE2 rel = truth(0).inverse() * truth(3 * dt);
  EXPECT_LT(1e3 * std::hypot(tr.pose().x - rel.x, tr.pose().y - rel.y), 0.05);
  EXPECT_THROW(tr.track(nullptr, f.cols, f.rows, f.step, 4 * dt), Error);
  EXPECT_THROW(tr.track(f.data, f.cols, f.rows, f.cols - 1, 4 * dt), Error);
}

TEST(TrackWeakTexture, StripesLeaveTheMotionAlongThemUnconstrained) {
  // Straight stripes on the ground: motion along them changes nothing in the image. The frame
  // is Degraded ("motion poorly constrained"), the covariance says which direction is free,
  // and nothing is NaN.
  ocl::Runtime rt;
  test::ScratchDir dir;
  cv::Mat tex(512, 512, CV_8UC1);
  for (int y = 0; y < tex.rows; ++y)
    for (int x = 0; x < tex.cols; ++x)
      tex.at<uint8_t>(y, x) = static_cast<uint8_t>(128 + 60 * std::sin(2 * M_PI * x / 32.0));
  sim::Options so;
  so.camera = sim::default_camera(320, 240);
  so.camera.k1 = so.camera.k2 = 0.0;
  sim::Renderer renderer(rt, tex, so);
  Tracker tr(rt, so.camera, so.extrinsics);
  // Stripes run along the world y axis (texture v); the robot faces +y and drives along them.
  const SE2 a(0.0, 0.0, M_PI / 2), m(0.01, 0.0, 0.0);
  auto frame = [&](const SE2& p) {
    return test::test_upload(rt, test::test_pyramid(renderer.render_float(p), nullptr, 4));
  };
  tr.track(frame(a), 0.0);
  const FrameResult r = tr.track(frame(a * m), dt);
  std::printf("status %s (%s), motion %.5f %.5f %.5f, std x %.3g m, y %.3g m, theta %.3g rad\n",
              status_name(r.status), r.reason, r.motion.value.x, r.motion.value.y, r.motion.value.theta,
              std::sqrt(r.motion.covariance(0, 0)), std::sqrt(r.motion.covariance(1, 1)), std::sqrt(r.motion.covariance(2, 2)));
  EXPECT_STATUS(r, Degraded);
  EXPECT_STREQ(r.reason, "motion poorly constrained");
  // Forward (x, along the stripes) is free, sideways and the heading are not.
  EXPECT_GT(r.motion.covariance(0, 0), 100 * r.motion.covariance(1, 1));
  EXPECT_LT(std::abs(r.motion.value.y - m.y), 1e-4);
  EXPECT_LT(std::abs(r.motion.value.theta - m.theta), 1e-3);
}

TEST_F(TrackBadInput, ResetStartsOver) {
  track(good(0), 0);
  track(good(dt), dt);
  tracker_->reset();
  EXPECT_EQ(tracker_->pose().x, 0.0);
  EXPECT_STATUS(track(good(2 * dt), 2 * dt), First);
  EXPECT_STATUS(track(good(3 * dt), 3 * dt), Ok);
}

// Extrinsics that cannot be a camera over the ground: not finite, or pitched so that no part of
// the image looks below the horizon (issue 27: accepted, then every frame Lost, or Ok on a sky).
// A steep rear camera (40 degrees from horizontal) and a strongly rolled one are fine.
TEST(TrackerExtrinsics, NotFiniteOrLookingUpIsInvalidArgument) {
  ocl::Runtime rt;
  const CameraModel cam = sim::default_camera(160, 120);
  const Extrinsics good{0.2, 0.0, 0.3, 0.2, 0.3, 0.0};
  EXPECT_NO_THROW(Tracker(rt, cam, good));
  EXPECT_NO_THROW(Tracker(rt, cam, Extrinsics{-1.0, 0.0, 0.9, 0.0, 40.0 * M_PI / 180.0, M_PI}));
  EXPECT_NO_THROW(Tracker(rt, cam, Extrinsics{0.25, 0.05, 0.12, -27.0 * M_PI / 180.0, 0.14, 0.0}));
  for (double bad : {std::nan(""), HUGE_VAL}) {
    Extrinsics e = good;
    e.roll = bad;
    EXPECT_THROW(Tracker(rt, cam, e), Error);
    e = good;
    e.yaw = bad;
    EXPECT_THROW(Tracker(rt, cam, e), Error);
  }
  // Looking straight down is pitch 0; at 150 degrees the optical axis is 60 degrees above the
  // horizon and the image's lowest row (the 80-degree camera is 64 degrees high) still above it.
  for (double pitch_deg : {150.0, 180.0}) {
    Extrinsics e = good;
    e.pitch = pitch_deg * M_PI / 180.0;
    try {
      Tracker t(rt, cam, e);
      ADD_FAILURE() << "pitch " << pitch_deg << " deg accepted";
    } catch (const Error& err) {
      EXPECT_EQ(err.code(), ErrorCode::InvalidArgument) << pitch_deg;
    }
  }
}

// An image too small for the pyramid is refused when the tracker is made, naming the size, the
// levels and what the coarsest level would be (issue 27: a 1x1 camera failed inside the aligner
// with an internal "WarpReduce::run" message). level_size is ceil(w / 2^l): a 32x32 image has a
// 4x4 coarsest level at 4 levels, a 31-pixel side 4 too, 24 gives 3.
TEST(TrackerCamera, ImagesTooSmallForThePyramidAreInvalidArgument) {
  ocl::Runtime rt;
  const Extrinsics e{0.2, 0.0, 0.3, 0.2, 0.3, 0.0};
  const auto make = [&](int w, int h, int levels) {
    CameraModel cam = sim::default_camera(w, h);
    TrackerOptions o;
    o.levels = levels;
    Tracker t(rt, cam, e, o);
  };
  EXPECT_NO_THROW(make(32, 32, 4));
  EXPECT_NO_THROW(make(25, 25, 4));
  EXPECT_NO_THROW(make(4, 4, 1));
  for (const auto& [w, h, levels, coarsest] :
       {std::tuple{1, 1, 1, "1x1"}, {1, 1, 4, "1x1"}, {24, 32, 4, "3x4"}, {64, 48, 5, "4x3"}, {3, 8, 1, "3x8"}}) {
    try {
      make(w, h, levels);
      ADD_FAILURE() << w << "x" << h << " at " << levels << " levels accepted";
    } catch (const Error& err) {
      EXPECT_EQ(err.code(), ErrorCode::InvalidArgument) << err.what();
      const std::string msg = err.what();
      EXPECT_NE(msg.find(std::to_string(w) + "x" + std::to_string(h) + " image"), std::string::npos) << msg;
      EXPECT_NE(msg.find("coarsest would be " + std::string(coarsest) + " pixels"), std::string::npos) << msg;
    }
  }
}

}  // namespace
}  // namespace planarvo::track
