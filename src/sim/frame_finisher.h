// Internal to src/sim: the host's half of simulate(), run beside the device. While the device
// renders frame k + 1, worker threads finish the frames rendered before it: the camera's light
// (apply_lighting), its response and noise (apply_camera) and the PNG. Each frame's noise comes
// from its own seed, so the files are the same whatever the threads' order.
#pragma once
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "sim/simulator.h"

namespace planarvo::sim {

class FrameFinisher {
 public:
  // threads workers; at most max_pending rendered frames wait for one (submit blocks beyond).
  FrameFinisher(const Options& options, const Lighting& lighting, const std::vector<Exposure>& exposure,
                int threads, size_t max_pending);
  // Stops the workers; frames not yet finished are dropped (after an error or a cancellation).
  ~FrameFinisher();
  FrameFinisher(const FrameFinisher&) = delete;
  FrameFinisher& operator=(const FrameFinisher&) = delete;

  // Queues frame k's clean render (CV_32FC1) to be written to path. Rethrows a worker's error.
  void submit(size_t k, cv::Mat clean, std::string path);
  // Waits until every submitted frame is written; rethrows a worker's error.
  void finish();
  // Seconds the workers spent, summed over them (they overlap the render and each other).
  double camera_seconds() const { return camera_; }
  double write_seconds() const { return write_; }

 private:
  struct Job {
    size_t k;
    cv::Mat clean;
    std::string path;
  };
  void work();
  void rethrow_locked();

  const Options& options_;
  const Lighting& lighting_;
  const std::vector<Exposure>& exposure_;
  const size_t max_pending_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> jobs_;
  size_t busy_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
  double camera_ = 0.0, write_ = 0.0;
  std::vector<std::thread> threads_;
};

// One frame's PNG, lossless (zlib's Huffman-only strategy: faster than level 1 and smaller for
// noisy images); Error(Io) naming the file when it cannot be written.
void write_png(const std::string& path, const cv::Mat& image);

}  // namespace planarvo::sim
