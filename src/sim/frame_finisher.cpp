// The simulator's frames finished on the host beside the device (frame_finisher.h).
#include "sim/frame_finisher.h"

#include <chrono>
#include <utility>

#include <opencv2/imgcodecs.hpp>

#include "core/error.h"

namespace planarvo::sim {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

void write_png(const std::string& path, const cv::Mat& image) {
  static const std::vector<int> png = {cv::IMWRITE_PNG_COMPRESSION, 1, cv::IMWRITE_PNG_STRATEGY,
                                       cv::IMWRITE_PNG_STRATEGY_HUFFMAN_ONLY};
  bool ok = false;
  try {
    ok = cv::imwrite(path, image, png);
  } catch (const cv::Exception& e) {
    throw Error(ErrorCode::Io, path + ": cannot be written (" + e.err + ")");
  }
  if (!ok) throw Error(ErrorCode::Io, path + ": cannot be written");
}

FrameFinisher::FrameFinisher(const Options& options, const Lighting& lighting, const std::vector<Exposure>& exposure,
                             int threads, size_t max_pending)
    : options_(options), lighting_(lighting), exposure_(exposure), max_pending_(max_pending < 1 ? 1 : max_pending) {
  for (int i = 0; i < (threads < 1 ? 1 : threads); ++i) threads_.emplace_back([this] { work(); });
}

FrameFinisher::~FrameFinisher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    jobs_.clear();
  }
  changed_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void FrameFinisher::rethrow_locked() {
  if (error_) std::rethrow_exception(error_);
}

void FrameFinisher::submit(size_t k, cv::Mat clean, std::string path) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return error_ || jobs_.size() < max_pending_; });
  rethrow_locked();
  jobs_.push_back({k, std::move(clean), std::move(path)});
  lock.unlock();
  changed_.notify_all();
}

void FrameFinisher::finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return error_ || (jobs_.empty() && busy_ == 0); });
  rethrow_locked();
}

void FrameFinisher::work() {
  for (;;) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return stop_ || !jobs_.empty(); });
    if (stop_) return;
    Job job = std::move(jobs_.front());
    jobs_.pop_front();
    ++busy_;
    lock.unlock();
    changed_.notify_all();  // a place in the queue is free
    double camera = 0.0, write = 0.0;
    std::exception_ptr error;
    try {
      auto t0 = std::chrono::steady_clock::now();
      apply_lighting(lighting_, job.clean);
      const cv::Mat image = apply_camera(job.clean, exposure_[job.k], options_.pixel_noise,
                                         derive_seed(options_.seed, 1000 + job.k));
      camera = seconds_since(t0);
      t0 = std::chrono::steady_clock::now();
      write_png(job.path, image);
      write = seconds_since(t0);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    --busy_;
    camera_ += camera;
    write_ += write;
    if (error && !error_) error_ = error;
    lock.unlock();
    changed_.notify_all();
  }
}

}  // namespace planarvo::sim
