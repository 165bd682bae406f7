// What happened to the frames, for the summary the node logs on shutdown and the `~counts` topic
// (std_msgs/String, latched, "key: value" lines: YAML).
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace planarvo_node {

// Times in milliseconds, kept as a histogram (0.05 ms bins up to 1 s, one bin above) so that a node
// that runs for days holds and copies a fixed size.
class MsHistogram {
 public:
  void add(double ms) {
    const double b = ms / kBin;
    bins_[b >= static_cast<double>(kBins - 1) ? kBins - 1 : b > 0 ? static_cast<size_t>(b) : 0] += 1;
    ++count_;
    max_ = std::max(max_, ms);
  }
  double median() const {
    int64_t seen = 0;
    for (size_t i = 0; i < kBins; ++i)
      if ((seen += bins_[i]) * 2 > count_) return (static_cast<double>(i) + 0.5) * kBin;
    return 0;
  }
  double max() const { return max_; }

 private:
  static constexpr double kBin = 0.05;
  static constexpr size_t kBins = 20001;
  std::vector<int64_t> bins_ = std::vector<int64_t>(kBins, 0);
  int64_t count_ = 0;
  double max_ = 0;
};

struct FrameCounts {
  int64_t received = 0;   // image messages that reached the node
  int64_t tracked = 0;    // ... given to the tracker (first, ok, degraded or lost)
  int64_t published = 0;  // odometry messages published (one per tracked frame)
  int64_t ok = 0, degraded = 0, lost = 0;
  int64_t calibration_frames = 0;  // frames fed to the live calibration
  // Frames received but not tracked, by why:
  int64_t dropped_queue_full = 0;  // the oldest waiting frame, when ~max_pending were waiting
  int64_t rejected = 0;            // bad encoding, size, or a size that disagrees with the camera
  int64_t no_camera = 0;           // no camera (camera_info never came) when the node stopped
  int64_t not_tracked = 0;         // calibration only: no extrinsics yet
  int64_t unprocessed = 0;         // still queued when ~drain_seconds ran out at shutdown
  int64_t failed = 0;              // the tracker returned an error
  int64_t seq_gaps = 0;            // image header seq numbers skipped before the node (not received)
  int64_t max_queue = 0;           // most frames waiting at once
  MsHistogram process_ms, engine_ms;  // per tracked frame: node wall time, the engine's time
  double max_latency_ms = 0;                  // receipt to published

  int64_t dropped() const { return dropped_queue_full + rejected + no_camera + unprocessed + failed; }

  std::string yaml() const {
    char b[1024];
    std::snprintf(b, sizeof b,
                  "received: %lld\ntracked: %lld\npublished: %lld\nok: %lld\ndegraded: %lld\nlost: %lld\n"
                  "dropped: %lld\ndropped_queue_full: %lld\nrejected: %lld\nno_camera: %lld\nunprocessed: %lld\n"
                  "failed: %lld\nnot_tracked: %lld\nseq_gaps: %lld\ncalibration_frames: %lld\nmax_queue: %lld\n"
                  "median_ms: %.3f\nmax_ms: %.3f\nengine_median_ms: %.3f\nmax_latency_ms: %.3f\n",
                  ll(received), ll(tracked), ll(published), ll(ok), ll(degraded), ll(lost), ll(dropped()),
                  ll(dropped_queue_full), ll(rejected), ll(no_camera), ll(unprocessed), ll(failed), ll(not_tracked),
                  ll(seq_gaps), ll(calibration_frames), ll(max_queue), process_ms.median(), process_ms.max(),
                  engine_ms.median(), max_latency_ms);
    return b;
  }

  std::string summary() const {
    char b[1024];
    std::snprintf(b, sizeof b,
                  "planarvo_node: frames received %lld, tracked %lld (%lld ok, %lld degraded, %lld lost), odometry "
                  "published %lld; dropped %lld (queue full %lld, rejected %lld, no camera %lld, unprocessed at "
                  "shutdown %lld, tracker errors %lld); not tracked (calibrating) %lld; upstream seq gaps %lld; "
                  "per frame median %.2f ms, max %.2f ms (engine median %.2f ms); latency max %.1f ms; queue max %lld",
                  ll(received), ll(tracked), ll(ok), ll(degraded), ll(lost), ll(published), ll(dropped()),
                  ll(dropped_queue_full), ll(rejected), ll(no_camera), ll(unprocessed), ll(failed), ll(not_tracked),
                  ll(seq_gaps), process_ms.median(), process_ms.max(), engine_ms.median(), max_latency_ms,
                  ll(max_queue));
    return b;
  }

 private:
  static long long ll(int64_t v) { return static_cast<long long>(v); }
};

}  // namespace planarvo_node
