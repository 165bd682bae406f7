// The photometric model on the device (photometric.h, PhotometricModel): its two planes and the
// statistics' two, the count of frames learnt, and its refits, blocking or on a worker thread
// (README.md, "Refits beside the tracking"). The fit itself is photometric.cpp's.
#include "image/photometric.h"

#include <future>
#include <string>
#include <vector>

#include "core/error.h"
#include "ocl/runtime.h"

namespace planarvo {

struct PhotometricModel::Impl {
  ocl::Runtime& rt;
  PhotometricOptions options;
  cv::Mat valid;
  int width = 0, height = 0;
  cl::Buffer model, stats;
  PhotometricFit fit, known;
  bool has_known = false;
  int frames = 0, frames_at_fit = 0;
  long revision = 0;
  // A refit in the background (start_refit): the statistics' copy it reads and its result.
  std::future<PhotometricFit> pending;

  // Waits for a refit in the background and forgets it, its error too: what it would have fitted
  // is no longer wanted.
  void drop_pending() {
    if (!pending.valid()) return;
    try {
      pending.get();
    } catch (...) {  // NOLINT(bugprone-empty-catch): the dropped refit's error is not the caller's
    }
  }

  Impl(ocl::Runtime& r, const cv::Mat& v, const PhotometricOptions& o)
      : rt(r), options(o), valid(v.clone()), width(v.cols), height(v.rows) {}

  size_t plane() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }

  void upload(const PhotometricFit& f) {
    const size_t bytes = plane() * sizeof(float);
    rt.queue().enqueueWriteBuffer(model, CL_TRUE, 0, bytes, f.scale.ptr<float>());
    rt.queue().enqueueWriteBuffer(model, CL_TRUE, bytes, bytes, f.offset.ptr<float>());
    fit = f;
    ++revision;
  }
};

PhotometricModel::PhotometricModel(ocl::Runtime& runtime, const cv::Mat& valid,
                                   const PhotometricOptions& options) {
  validate(options);
  if (valid.type() != CV_8UC1 || valid.empty())
    throw_invalid_argument("PhotometricModel: valid must be a non-empty CV_8UC1 image");
  impl_ = std::make_unique<Impl>(runtime, valid, options);
  Impl& m = *impl_;
  try {
    m.model = cl::Buffer(runtime.context(), CL_MEM_READ_ONLY, 2 * m.plane() * sizeof(float));
    m.stats = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE, 2 * m.plane() * sizeof(float));
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::OpenCL, std::string("photometric model: allocating buffers failed: ") +
                                       e.what() + " " + ocl::error_name(e.err()));
  }
  reset();
}

PhotometricModel::~PhotometricModel() {
  if (impl_) impl_->drop_pending();
}

const PhotometricOptions& PhotometricModel::options() const { return impl_->options; }
const cl::Buffer& PhotometricModel::model() const { return impl_->model; }
cl::Buffer& PhotometricModel::statistics() { return impl_->stats; }
int PhotometricModel::frames() const { return impl_->frames; }
const PhotometricFit& PhotometricModel::fit() const { return impl_->fit; }
long PhotometricModel::revision() const { return impl_->revision; }

bool PhotometricModel::learning() const { return impl_->options.learn && !impl_->has_known; }

float PhotometricModel::next_alpha() {
  Impl& m = *impl_;
  if (!learning()) return 0.0f;
  ++m.frames;
  return 1.0f / static_cast<float>(std::min(m.frames, m.options.memory_frames));
}

bool PhotometricModel::refit_due(bool needed) const {
  const Impl& m = *impl_;
  if (!learning() || m.frames < (needed ? m.options.min_frames : kPhotometricFirstFitFrames)) return false;
  const int since = m.frames - m.frames_at_fit;
  return m.frames_at_fit == 0 || since >= (needed ? 1 : std::max(4, m.frames_at_fit / 4));
}

void PhotometricModel::refit(bool needed) {
  Impl& m = *impl_;
  m.drop_pending();
  start_refit(needed);
  take_refit();
}

void PhotometricModel::start_refit(bool needed) {
  Impl& m = *impl_;
  if (m.pending.valid()) return;
  cv::Mat mean(m.height, m.width, CV_32FC1), square(m.height, m.width, CV_32FC1);
  const size_t bytes = m.plane() * sizeof(float);
  cl::Event read;
  try {
    m.rt.queue().enqueueReadBuffer(m.stats, CL_FALSE, 0, bytes, mean.ptr<float>());
    m.rt.queue().enqueueReadBuffer(m.stats, CL_FALSE, bytes, bytes, square.ptr<float>(), nullptr, &read);
    m.rt.queue().flush();  // the worker waits for the read; it must reach the device
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::OpenCL, std::string("photometric model: refit failed: ") + e.what() +
                                       " " + ocl::error_name(e.err()));
  }
  // The worker holds its own copies (cv::Mat shares, the options and counts are copied): the
  // model may be moved on, reset or destroyed before it ends (the destructor and reset wait).
  m.pending = std::async(std::launch::async, [read, mean, square, valid = m.valid, frames = m.frames,
                                             options = m.options, needed] {
    try {
      read.wait();  // in-order queue: both reads are done
    } catch (const cl::Error& e) {
      throw Error(ErrorCode::OpenCL, std::string("photometric model: reading the statistics failed: ") +
                                         e.what() + " " + ocl::error_name(e.err()));
    }
    return fit_photometric(mean, square, valid, frames, options, needed);
  });
  m.frames_at_fit = m.frames;
}

bool PhotometricModel::refit_pending() const { return impl_->pending.valid(); }

bool PhotometricModel::take_refit() {
  Impl& m = *impl_;
  if (!m.pending.valid()) return false;
  PhotometricFit fit = m.pending.get();  // rethrows the worker's error; pending is then empty
  try {
    m.upload(fit);
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::OpenCL, std::string("photometric model: uploading a refit failed: ") + e.what() +
                                       " " + ocl::error_name(e.err()));
  }
  return true;
}

void PhotometricModel::set(const PhotometricFit& fit) {
  Impl& m = *impl_;
  if (fit.scale.type() != CV_32FC1 || fit.offset.type() != CV_32FC1 || fit.scale.cols != m.width ||
      fit.scale.rows != m.height || fit.offset.size() != fit.scale.size())
    throw_invalid_argument("PhotometricModel::set: the model must be two CV_32FC1 images of " +
                           std::to_string(m.width) + "x" + std::to_string(m.height));
  m.known = fit;
  m.has_known = true;
  reset();
}

void PhotometricModel::reset() {
  Impl& m = *impl_;
  m.drop_pending();
  m.frames = m.frames_at_fit = 0;
  try {
    // A write, not clEnqueueFillBuffer: OpenCL 1.1 devices have none.
    const std::vector<float> zeros(2 * m.plane(), 0.0f);
    m.rt.queue().enqueueWriteBuffer(m.stats, CL_TRUE, 0, zeros.size() * sizeof(float), zeros.data());
    m.upload(m.has_known ? m.known : identity_photometric(m.width, m.height));
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::OpenCL, std::string("photometric model: reset failed: ") + e.what() +
                                       " " + ocl::error_name(e.err()));
  }
}

}  // namespace planarvo
