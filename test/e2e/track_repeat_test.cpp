// Tracking is repeatable: the same frames give bit-identical poses, motions and covariances from a
// second tracker on the same context, from a tracker after planarvo_tracker_reset, and from a
// tracker on a second context, through the C API. The property that bench_soak checks over an
// hour of frames, here on a short drive that the suite can afford.
#include <algorithm>
#include <cstring>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/test_util.h"
#include "ocl/runtime.h"
#include "planarvo/planarvo.h"
#include "sim/simulator.h"

namespace planarvo {
namespace {

struct ContextDeleter {
  void operator()(planarvo_context* c) const { planarvo_context_destroy(c); }
};
struct TrackerDeleter {
  void operator()(planarvo_tracker* t) const { planarvo_tracker_destroy(t); }
};
using ContextPtr = std::unique_ptr<planarvo_context, ContextDeleter>;
using TrackerPtr = std::unique_ptr<planarvo_tracker, TrackerDeleter>;

// 2 s of the simulator's mixed drive at 320x240, rendered in memory.
struct Drive {
  sim::Options options;
  std::vector<cv::Mat> frames;
  std::vector<double> t;
};

Drive render_drive() {
  Drive d;
  d.options.texture = test::texture("asphalt_01.png").string();
  d.options.camera = sim::default_camera(320, 240);
  d.options.seconds = 2.0;
  d.options.seed = 7;
  d.options.supersampling = 1;
  ocl::Runtime rt;
  const sim::Trajectory traj = sim::generate_trajectory(d.options);
  const std::vector<sim::Exposure> exposure = sim::exposure_series(d.options, traj.t);
  sim::Renderer renderer(rt, cv::imread(d.options.texture, cv::IMREAD_GRAYSCALE), d.options);
  for (size_t k = 0; k < traj.t.size(); ++k)
    d.frames.push_back(sim::apply_camera(renderer.render_float(traj.pose[k]), exposure[k], d.options.pixel_noise,
                                         sim::derive_seed(d.options.seed, 1000 + k)));
  d.t = traj.t;
  return d;
}

ContextPtr make_context() {
  planarvo_context* c = nullptr;
  EXPECT_EQ(planarvo_context_create(nullptr, &c), PLANARVO_OK) << planarvo_last_error();
  return ContextPtr(c);
}

TrackerPtr make_tracker(planarvo_context* ctx, const sim::Options& so) {
  const CameraModel& c = so.camera;
  const planarvo_camera camera{c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3, {0, 0, 0, 0}, 0.0, 0.0};
  const Extrinsics& e = so.extrinsics;
  const planarvo_extrinsics extrinsics{e.x, e.y, e.z, e.roll, e.pitch, e.yaw};
  planarvo_tracker* t = nullptr;
  EXPECT_EQ(planarvo_tracker_create(ctx, &camera, &extrinsics, nullptr, &t), PLANARVO_OK) << planarvo_last_error();
  return TrackerPtr(t);
}

// What a run gives per frame: status, pose, motion and covariance, compared bitwise.
struct FrameOutput {
  int32_t status;
  planarvo_se2 pose, motion;
  double covariance[9];
};

std::vector<FrameOutput> track(planarvo_tracker* tracker, const Drive& d) {
  std::vector<FrameOutput> out;
  for (size_t k = 0; k < d.frames.size(); ++k) {
    const cv::Mat& f = d.frames[k];
    const planarvo_image image{f.data, f.cols, f.rows, f.step, PLANARVO_GRAY8};
    planarvo_track_result r{};
    r.struct_size = sizeof r;
    EXPECT_EQ(planarvo_tracker_track(tracker, &image, d.t[k], &r), PLANARVO_OK) << planarvo_last_error();
    FrameOutput o{};
    o.status = r.status;
    o.pose = r.pose;
    o.motion = r.motion;
    std::memcpy(o.covariance, r.covariance, sizeof o.covariance);
    out.push_back(o);
  }
  return out;
}

// The number of frames whose output differs from the reference in any bit.
int differing_frames(const std::vector<FrameOutput>& a, const std::vector<FrameOutput>& b) {
  EXPECT_EQ(a.size(), b.size());
  int n = 0;
  for (size_t k = 0; k < std::min(a.size(), b.size()); ++k)
    n += a[k].status != b[k].status || std::memcmp(&a[k].pose, &b[k].pose, sizeof a[k].pose) != 0 ||
         std::memcmp(&a[k].motion, &b[k].motion, sizeof a[k].motion) != 0 ||
         std::memcmp(a[k].covariance, b[k].covariance, sizeof a[k].covariance) != 0;
  return n;
}

TEST(TrackRepeat, SameFramesGiveBitIdenticalResults) {
  const Drive d = render_drive();
  ContextPtr ctx = make_context();
  ASSERT_TRUE(ctx);
  TrackerPtr first = make_tracker(ctx.get(), d.options);
  ASSERT_TRUE(first);
  const std::vector<FrameOutput> reference = track(first.get(), d);
  int tracked = 0;
  for (const FrameOutput& o : reference) tracked += o.status == PLANARVO_TRACK_OK;
  EXPECT_EQ(tracked, static_cast<int>(d.frames.size()) - 1);  // every frame after the first

  // The same tracker after a reset: it must forget everything (keyframe, pose, velocity
  // prediction, brightness), or the second pass starts from a different guess.
  ASSERT_EQ(planarvo_tracker_reset(first.get()), PLANARVO_OK);
  EXPECT_EQ(differing_frames(reference, track(first.get(), d)), 0);

  // A second tracker on the same context, while the first still exists.
  TrackerPtr second = make_tracker(ctx.get(), d.options);
  ASSERT_TRUE(second);
  EXPECT_EQ(differing_frames(reference, track(second.get(), d)), 0);

  // A tracker on a second context (its own queue and programs).
  ContextPtr other = make_context();
  ASSERT_TRUE(other);
  TrackerPtr third = make_tracker(other.get(), d.options);
  ASSERT_TRUE(third);
  EXPECT_EQ(differing_frames(reference, track(third.get(), d)), 0);
}

}  // namespace
}  // namespace planarvo
