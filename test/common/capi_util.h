// The C API's handles as owning pointers, and a data set tracked frame by frame through the C API:
// the reference that the tool's outputs are compared with.
#pragma once
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "planarvo/planarvo.h"

namespace planarvo::test {

struct ApiDeleter {
  void operator()(planarvo_context* c) const { planarvo_context_destroy(c); }
  void operator()(planarvo_dataset* d) const { planarvo_dataset_destroy(d); }
  void operator()(planarvo_tracker* t) const { planarvo_tracker_destroy(t); }
};
using ApiContext = std::unique_ptr<planarvo_context, ApiDeleter>;
using ApiDataset = std::unique_ptr<planarvo_dataset, ApiDeleter>;
using ApiTracker = std::unique_ptr<planarvo_tracker, ApiDeleter>;

inline ApiContext api_context() {
  planarvo_context* c = nullptr;
  EXPECT_EQ(planarvo_context_create(nullptr, &c), PLANARVO_OK) << planarvo_last_error();
  return ApiContext(c);
}

inline ApiDataset api_dataset(const std::string& dir) {
  planarvo_dataset* d = nullptr;
  EXPECT_EQ(planarvo_dataset_open(dir.c_str(), nullptr, &d), PLANARVO_OK) << planarvo_last_error();
  return ApiDataset(d);
}

inline planarvo_dataset_info api_info(const planarvo_dataset* d) {
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  EXPECT_EQ(planarvo_dataset_info_get(d, &info), PLANARVO_OK) << planarvo_last_error();
  return info;
}

// b in a's frame: a^-1 b, the angle wrapped to [-pi, pi].
inline planarvo_se2 between(const planarvo_se2& a, const planarvo_se2& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta), dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, std::remainder(b.theta - a.theta, 2 * M_PI)};
}

struct TrackedFrame {
  planarvo_frame_data data;
  planarvo_track_result result;
};

// Every frame of the data set at path (a folder, or a bag with options) tracked with the
// tracker's default options and the given extrinsics; the data set's info in *info when asked.
inline std::vector<TrackedFrame> track_through_api(const std::string& path, const planarvo_extrinsics& extrinsics,
                                                   const planarvo_dataset_options* options = nullptr,
                                                   planarvo_dataset_info* info_out = nullptr) {
  ApiContext context = api_context();
  planarvo_dataset* d = nullptr;
  EXPECT_EQ(planarvo_dataset_open(path.c_str(), options, &d), PLANARVO_OK) << planarvo_last_error();
  ApiDataset dataset(d);
  std::vector<TrackedFrame> frames;
  if (!context || !dataset) return frames;
  const planarvo_dataset_info info = api_info(dataset.get());
  if (info_out) *info_out = info;
  planarvo_tracker* t = nullptr;
  EXPECT_EQ(planarvo_tracker_create(context.get(), &info.camera, &extrinsics, nullptr, &t), PLANARVO_OK)
      << planarvo_last_error();
  ApiTracker tracker(t);
  if (!tracker) return frames;
  for (int64_t i = 0; i < info.frame_count; ++i) {
    TrackedFrame f{};
    EXPECT_EQ(planarvo_dataset_frame_data(dataset.get(), i, &f.data), PLANARVO_OK) << planarvo_last_error();
    planarvo_image image{};
    EXPECT_EQ(planarvo_dataset_frame(dataset.get(), i, &image), PLANARVO_OK) << planarvo_last_error();
    f.result.struct_size = sizeof f.result;
    EXPECT_EQ(planarvo_tracker_track(tracker.get(), &image, f.data.timestamp, &f.result), PLANARVO_OK)
        << planarvo_last_error();
    frames.push_back(f);
  }
  return frames;
}

// The accuracy of tracked motions against the data set's ground truth, as `planarvo track`
// defines it (intervals after frames that were tracked, gross above 1 mm).
// The accuracy of the tracked motions against the data set's truth over every interval (what
// `planarvo track` reports first), or, with `only`, over the intervals whose last frame has that
// status.
inline planarvo_motion_accuracy accuracy_of(const std::vector<TrackedFrame>& frames, int only = -1) {
  const size_t n = frames.size();
  std::vector<planarvo_se2> estimated, truth;
  std::vector<double> dt;
  std::vector<int32_t> valid;
  for (size_t i = 1; i < n; ++i) {
    const TrackedFrame &a = frames[i - 1], &b = frames[i];
    estimated.push_back(b.result.motion);
    truth.push_back(between(a.data.groundtruth, b.data.groundtruth));
    dt.push_back(b.data.timestamp - a.data.timestamp);
    valid.push_back(only < 0 || static_cast<int>(b.result.status) == only);
  }
  planarvo_motion_accuracy a{};
  a.struct_size = sizeof a;
  EXPECT_EQ(planarvo_evaluate_motions(estimated.data(), truth.data(), dt.data(), only < 0 ? nullptr : valid.data(),
                                      estimated.size(), 1e-3, &a),
            PLANARVO_OK)
      << planarvo_last_error();
  return a;
}

}  // namespace planarvo::test
