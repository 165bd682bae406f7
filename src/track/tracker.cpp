#include "track/tracker.h"

#include "track/tracker_impl.h"

namespace planarvo::track {

const char* status_name(FrameResult::Status s) {
  switch (s) {
    case Status::First: return "first";
    case Status::Ok: return "ok";
    case Status::Degraded: return "degraded";
    case Status::Lost: return "lost";
  }
  return "?";
}

WarpReduceOptions TrackerOptions::default_kernel_options() {
  // WarpReduceOptions' defaults are the measured best on PoCL (README.md).
  return WarpReduceOptions();
}

MountingWatchOptions Tracker::Impl::watch_options(const TrackerOptions& o, const Extrinsics& e) {
  MountingWatchOptions w = o.mounting_watch;
  w.height = e.z;
  return w;
}

const PhotometricFit* Tracker::Impl::photometric_model() const {
  if (known_photometric) return &*known_photometric;
  const PhotometricModel* m = pipeline ? pipeline->photometric() : nullptr;
  if (!m) return nullptr;
  const PhotometricFit& f = m->fit();
  if (f.frames == 0) return nullptr;
  for (int y = 0; y < f.scale.rows; ++y)
    for (int x = 0; x < f.scale.cols; ++x)
      if (f.scale.at<float>(y, x) != 1.0f || f.offset.at<float>(y, x) != 0.0f) return &f;
  return nullptr;  // fitted, but the statistics found no light fixed to the camera
}

void Tracker::Impl::reset() {
  forget_alignment(nullptr);
  has_keyframe = false;
  pose = SE2();
  light_gate.learnt();
  prev = Estimate();
  prev_predicted = false;
  prev_covariance.setZero();
  prev_tilt.setZero();
  plane.reset();
  watch.reset();
  last_odometry.reset();
  keyframe_shear_assumed = false;
  velocity.setZero();
  readout_twist.reset();
  lost_in_a_row = 0;
  live_twist = live_offset = Eigen::Vector3d::Zero();
  has_t = false;
  nominal_dt = 0.0;
  since_good = 0.0;
  sigma.fill(opt.initial_sigma);
}

FrameResult Tracker::Impl::track_gray(const uint8_t* gray, int width, int height, size_t stride, double t) {
  if (!gray) throw_invalid_argument("Tracker::track: the image is null");
  forget_alignment(kNotAligned);  // the pipeline is about to overwrite the live slot
  if (width > 0 && stride < static_cast<size_t>(width))
    throw_invalid_argument("Tracker::track: stride " + std::to_string(stride) + " < width " +
                           std::to_string(width));
  if (width != camera.width || height != camera.height) return track(Pyramid(), t);
  const auto t0 = std::chrono::steady_clock::now();
  if (!pipeline) {
    ImagePipelineOptions po;
    po.prefilter = opt.prefilter;
    po.decorrelate_noise = opt.decorrelate_noise;
    po.photometric = opt.photometric;
    pipeline = std::make_unique<ImagePipeline>(rt, camera, opt.levels, po);
    if (known_photometric && pipeline->photometric()) pipeline->photometric()->set(*known_photometric);
  }
  if (camera.timed_rows()) {  // a rolling shutter or an exposure: undistorted with the twist
    // Undistorted with the constant-velocity prediction's twist (track() measures it).
    live_twist = has_keyframe ? readout_twist.predict(t) : Eigen::Vector3d::Zero();
    pipeline->set_row_warp(rolling_shutter_warp(camera, ext, live_twist));
  }
  ++camera_frames;
  pipeline->process(gray, width, height, stride, slots[live_slot]);
  // Waiting here costs one synchronisation (the first pass would wait anyway) and splits
  // the frame's time between the pipeline and the tracker.
  rt.queue().finish();
  take_young_refit();
  const auto t1 = std::chrono::steady_clock::now();
  FrameResult r = track(slots[live_slot], t);
  learn_photometric(r);
  start_young_refit();
  r.pipeline_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  r.ms += r.pipeline_ms;
  return r;
}

bool Tracker::Impl::right_size(const Pyramid& live) const {
  if (live.num_levels() < 1) return false;
  for (int l = 0; l < live.num_levels(); ++l) {
    const PyramidLevel& p = live.levels[static_cast<size_t>(l)];
    if (p.width != level_size(camera.width, l) || p.height != level_size(camera.height, l) || !p.data())
      return false;
  }
  return true;
}

Tracker::Tracker(ocl::Runtime& runtime, const CameraModel& camera, const Extrinsics& extrinsics,
                 const TrackerOptions& options)
    : impl_(std::make_unique<Impl>(runtime, camera, extrinsics, options)) {}

Tracker::~Tracker() = default;

FrameResult Tracker::track(const Pyramid& live, double timestamp) { return impl_->track(live, timestamp); }
FrameResult Tracker::track(const uint8_t* gray, int width, int height, size_t stride, double timestamp) {
  return impl_->track_gray(gray, width, height, stride, timestamp);
}
void Tracker::reset() { impl_->reset(); }
void Tracker::set_odometry(const SE2& pose) { impl_->next_odometry = pose; }
ResidualImage Tracker::residuals(int level) { return impl_->residuals(level); }
const SE2& Tracker::pose() const { return impl_->pose; }
const TrackerOptions& Tracker::options() const { return impl_->opt; }
const PhotometricFit* Tracker::photometric_model() const { return impl_->photometric_model(); }

}  // namespace planarvo::track
