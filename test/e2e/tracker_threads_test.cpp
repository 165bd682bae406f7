// Several trackers in threads, one per camera, as the header's thread-safety rules allow (each
// thread its own context and tracker): every thread's motions are bit-identical to the same
// camera tracked alone, and accurate against the simulator's truth. The sanitizer script runs
// this test under ThreadSanitizer too (scripts/test.sh).
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capi/convert.h"
#include "common/test_util.h"
#include "ocl/runtime.h"
#include "planarvo/planarvo.h"
#include "sim/simulator.h"

namespace planarvo {
namespace {

constexpr int kFrames = 24;
constexpr double kRate = 30.0;

struct Camera {
  sim::Options options;
  std::vector<cv::Mat> frames;
  std::vector<SE2> truth;  // robot poses
};

// A drive with a turn, seen by a camera over its own texture.
Camera make_camera(ocl::Runtime& rt, const std::string& texture, int config) {
  Camera c;
  c.options.texture = test::texture(texture).string();
  c.options.camera = sim::default_camera(320, 240);
  c.options.extrinsics = sim::paper_configuration(config);
  c.options.supersampling = 1;
  sim::Renderer renderer(rt, cv::imread(c.options.texture, cv::IMREAD_GRAYSCALE), c.options);
  SE2 pose;
  for (int i = 0; i < kFrames; ++i) {
    c.truth.push_back(pose);
    c.frames.push_back(renderer.render(pose));
    pose = pose * SE2{0.4 / kRate, 0.0, (0.3 + 0.05 * i) / kRate};
  }
  return c;
}

// Tracks one camera through the C API with its own context; the motions, flattened.
std::vector<double> track(const Camera& c) {
  std::vector<double> out;
  planarvo_context_options co;
  planarvo_context_options_init(&co);
  planarvo_context* context = nullptr;
  if (planarvo_context_create(&co, &context) != PLANARVO_OK) return out;
  const planarvo_camera camera = capi::to_c(c.options.camera);
  const planarvo_extrinsics extrinsics = capi::to_c(c.options.extrinsics);
  planarvo_tracker* tracker = nullptr;
  if (planarvo_tracker_create(context, &camera, &extrinsics, nullptr, &tracker) == PLANARVO_OK) {
    for (int i = 0; i < kFrames; ++i) {
      const cv::Mat& f = c.frames[static_cast<size_t>(i)];
      const planarvo_image image{f.data, f.cols, f.rows, f.step, PLANARVO_GRAY8};
      planarvo_track_result r;
      r.struct_size = sizeof r;
      if (planarvo_tracker_track(tracker, &image, i / kRate, &r) != PLANARVO_OK) break;
      out.insert(out.end(), {r.motion.x, r.motion.y, r.motion.theta, static_cast<double>(r.status)});
    }
    planarvo_tracker_destroy(tracker);
  }
  planarvo_context_destroy(context);
  return out;
}

TEST(TrackerThreads, SeveralTrackersInThreadsMatchTheSameTrackersAlone) {
  std::vector<Camera> cameras;
  {
    ocl::Runtime rt;
    cameras.push_back(make_camera(rt, "asphalt_01.png", 1));
    cameras.push_back(make_camera(rt, "brick_floor.png", 2));
    cameras.push_back(make_camera(rt, "aerial_ground_rock.png", 1));
  }
  std::vector<std::vector<double>> alone, threaded(cameras.size());
  for (const Camera& c : cameras) alone.push_back(track(c));
  std::vector<std::thread> threads;
  for (size_t k = 0; k < cameras.size(); ++k)
    threads.emplace_back([&, k] { threaded[k] = track(cameras[k]); });
  for (std::thread& t : threads) t.join();

  for (size_t k = 0; k < cameras.size(); ++k) {
    SCOPED_TRACE("camera " + std::to_string(k));
    ASSERT_EQ(alone[k].size(), 4u * kFrames);
    ASSERT_EQ(threaded[k].size(), alone[k].size());
    EXPECT_EQ(std::memcmp(threaded[k].data(), alone[k].data(), alone[k].size() * sizeof(double)), 0);
    // And right: each motion against the truth, within a millimetre and a milliradian.
    for (int i = 1; i < kFrames; ++i) {
      const SE2 truth = cameras[k].truth[static_cast<size_t>(i - 1)].inverse() * cameras[k].truth[static_cast<size_t>(i)];
      const double* m = &alone[k][4 * static_cast<size_t>(i)];
      EXPECT_EQ(m[3], static_cast<double>(PLANARVO_TRACK_OK)) << "frame " << i;
      EXPECT_NEAR(m[0], truth.x, 1e-3) << "frame " << i;
      EXPECT_NEAR(m[1], truth.y, 1e-3) << "frame " << i;
      EXPECT_NEAR(m[2], truth.theta, 1e-3) << "frame " << i;
    }
  }
}

}  // namespace
}  // namespace planarvo
