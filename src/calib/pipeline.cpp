#include "calib/pipeline.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <chrono>
#include <cmath>

#include <opencv2/core.hpp>

#include "calib/motion_samples.h"
#include "calib/tilt_propagation.h"
#include "core/error.h"
#include "io/dataset/dataset.h"

namespace planarvo::calib {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct HeldFrame {
  cv::Mat gray;
  double t = 0.0;
  std::optional<SE2> odometry;
  std::optional<int> direction;
};

}  // namespace

graph::CalibrationOptions PipelineOptions::default_graph_options() {
  graph::CalibrationOptions o;
  // The camera's motions are micrometre-precise, so the residuals measure the odometry's noise.
  o.estimate_odometry_noise = true;
  return o;
}

const char* status_name(PipelineReport::Status s) {
  switch (s) {
    case PipelineReport::Status::Ok: return "ok";
    case PipelineReport::Status::TooLittleTexture: return "too little texture";
    case PipelineReport::Status::TooLittleMotion: return "too little motion";
    case PipelineReport::Status::Unobservable: return "unobservable";
    case PipelineReport::Status::Failed: return "failed";
  }
  return "?";
}

struct CameraCalibrator::Impl {
  enum class Stage { RollPitch, Tracking, Stopped, Finished };

  ocl::Runtime& rt;
  CameraModel camera;
  PipelineOptions opt;
  bool estimating_readout = false;
  Stage stage = Stage::RollPitch;  // frames are held (for roll and pitch, the readout time)
  std::unique_ptr<track::RollPitchEstimator> roll_pitch;
  bool roll_pitch_complete = false;  // its map is complete: later held frames are not its
  std::vector<HeldFrame> held;
  std::unique_ptr<track::Tracker> tracker;
  MotionSampler sampler;
  std::vector<double> frame_ms;
  std::vector<io::StampedPose> odometry_samples;  // add_odometry's samples from the last one at or before a frame
  PipelineReport report;
  Clock::time_point start = Clock::now();

  static const PipelineOptions& validated(const PipelineOptions& o) {
    if (!o.estimate_roll_pitch && !o.initial)
      throw_invalid_argument("calibration: roll and pitch are not estimated, so initial extrinsics must give them");
    if (o.graph.method == graph::CalibrationMethod::Nonholonomic && !o.graph.fix_scale)
      throw_invalid_argument("calibration: the nonholonomic method cannot estimate the camera height: give the height");
    if (o.max_buffered_frames < 2) throw_invalid_argument("calibration: max_buffered_frames must be at least 2");
    if (!o.accept_unusual_extrinsics) {
      if (o.initial) check_plausible_extrinsics(*o.initial, "calibration: the initial extrinsics", false);
      if (o.graph.fix_scale) check_plausible_height(o.graph.fixed_scale, "calibration: the camera height given");
    }
    return o;
  }

  // Stage 1's options: from the initial extrinsics' tilt (straight down without them), moved by
  // start_offset once another start was needed (retry_from_other_starts).
  track::RollPitchOptions roll_pitch_options() const {
    track::RollPitchOptions r = opt.roll_pitch;
    if (opt.initial) {
      r.initial_roll = opt.initial->roll;
      r.initial_pitch = opt.initial->pitch;
    }
    r.initial_roll += start_offset[0];
    r.initial_pitch += start_offset[1];
    return r;
  }
  std::array<double, 2> start_offset{0.0, 0.0};

  Impl(ocl::Runtime& r, const CameraModel& c, const PipelineOptions& o)
      : rt(r), camera(c), opt(validated(o)), estimating_readout(opt.readout == PipelineOptions::Readout::On) {
    if (opt.estimate_roll_pitch) {
      roll_pitch = std::make_unique<track::RollPitchEstimator>(rt, camera, roll_pitch_options());
    } else {
      report.roll_pitch.status = track::RollPitchResult::Status::Ok;
      report.roll_pitch.roll = opt.initial->roll;
      report.roll_pitch.pitch = opt.initial->pitch;
      if (!estimating_readout) start_tracking();
    }
  }

  // The tilt's uncertainty is carried into stage 3 when stage 1 estimated it.
  bool propagate_tilt() const { return opt.propagate_tilt && opt.estimate_roll_pitch; }

  void start_tracking() {
    report.readout_used = camera.rolling_shutter_readout;
    track::TrackerOptions to = opt.tracker;
    to.tilt_jacobian = to.tilt_jacobian || propagate_tilt();
    tracker = std::make_unique<track::Tracker>(rt, camera, stage2_extrinsics(report.roll_pitch.roll, report.roll_pitch.pitch),
                                               to);
    stage = Stage::Tracking;
  }

  void track(const uint8_t* gray, int width, int height, size_t stride, double t, const std::optional<SE2>& odometry,
             const std::optional<int>& direction) {
    const auto t0 = Clock::now();
    const track::FrameResult r = tracker->track(gray, width, height, stride, t);
    report.time.tracking += seconds_since(t0);
    sampler.add(r, t, odometry, direction);
    PipelineReport::Tracking& k = report.tracking;
    ++k.frames;
    k.engine_ms += r.ms;
    frame_ms.push_back(r.ms);
    k.keyframes += r.keyframe ? 1 : 0;
    switch (r.status) {
      case track::FrameResult::Status::First:
      case track::FrameResult::Status::Ok: ++k.ok; break;
      case track::FrameResult::Status::Degraded: ++k.degraded; break;
      case track::FrameResult::Status::Lost: ++k.lost; break;
    }
  }

  // Stage 1's estimate; false (and the pipeline stopped) when it failed.
  bool estimate_roll_pitch() {
    const auto t0 = Clock::now();
    report.roll_pitch = roll_pitch->estimate();
    if (worth_other_starts(report.roll_pitch)) retry_from_other_starts();
    report.time.roll_pitch += seconds_since(t0);
    if (report.roll_pitch.ok()) return true;
    stage = Stage::Stopped;
    report.status = report.roll_pitch.status == track::RollPitchResult::Status::TooLittleTexture
                        ? PipelineReport::Status::TooLittleTexture
                    : report.roll_pitch.status == track::RollPitchResult::Status::TooLittleMotion
                        ? PipelineReport::Status::TooLittleMotion
                        : PipelineReport::Status::Failed;
    report.reason = "roll and pitch: " + report.roll_pitch.reason;
    held.clear();
    roll_pitch.reset();
    return false;
  }

  // Whether stage 1 may have failed for want of a start near the camera's tilt: the keyframes did
  // not align, or too few were picked or too little motion seen, which a map tracked at a tilt far
  // from the camera's also gives (a car at 15 fps, camera pitched 35 deg: "moved too little in 90
  // frames (2 keyframes)" from straight down, 12 keyframes from 0.4 rad). Not for want of texture.
  // Standing still fails from every start, quickly (the standing-still test: 4 s in all).
  static bool worth_other_starts(const track::RollPitchResult& r) {
    using S = track::RollPitchResult::Status;
    return r.status == S::Failed || r.status == S::TooLittleMotion;
  }

  // Stage 1 again on the held frames from tilts 0.4 rad (23 deg) away from the first start, on the
  // axes and then the diagonals, until one succeeds. The map's tracker and the joint alignment
  // converge from about 0.3 rad off on an ordinary drive; a car at 15 fps with its camera pitched
  // 35 deg (gravel, 10 s at 640x480) failed from straight down and from 0.2 rad, and converged to
  // the truth (0.003 deg) from 0.4 rad. Costs nothing when the first start succeeds.
  static constexpr double kOtherStart = 0.4;
  static constexpr std::array<std::array<double, 2>, 8> kOtherStarts = {
      {{0, kOtherStart}, {0, -kOtherStart}, {kOtherStart, 0}, {-kOtherStart, 0},
       {kOtherStart, kOtherStart}, {kOtherStart, -kOtherStart}, {-kOtherStart, kOtherStart},
       {-kOtherStart, -kOtherStart}}};
  void retry_from_other_starts() {
    try_other_starts([] { return true; });
  }

  // A stage 1 estimator from the current start, fed the held frames until its map is complete.
  std::unique_ptr<track::RollPitchEstimator> estimator_on_held() const {
    auto e = std::make_unique<track::RollPitchEstimator>(rt, camera, roll_pitch_options());
    for (const HeldFrame& f : held)
      if (e->add_frame(f.gray.data, f.gray.cols, f.gray.rows, f.gray.step, f.t)) break;
    return e;
  }

  // Stage 1 on the held frames from each of kOtherStarts in turn: the first that succeeds and that
  // `keep` accepts (called with report.roll_pitch set to it) stays, and true is returned. Else the
  // start and report.roll_pitch are as they were.
  template <class Keep>
  bool try_other_starts(Keep&& keep) {
    const track::RollPitchResult first = report.roll_pitch;
    for (const std::array<double, 2>& s : kOtherStarts) {
      start_offset = s;
      track::RollPitchResult r = estimator_on_held()->estimate();
      if (!r.ok()) continue;
      report.roll_pitch = std::move(r);
      if (keep()) return true;
    }
    start_offset = {0.0, 0.0};
    report.roll_pitch = first;
    return false;
  }

  // The readout time from the held frames, tracked with the tilt known so far; when it finds a
  // rolling shutter, stage 1 runs again through it.
  bool estimate_readout() {
    const auto t0 = Clock::now();
    std::vector<cv::Mat> frames;
    std::vector<double> stamps;
    for (const HeldFrame& f : held)
      if (f.gray.cols == camera.width && f.gray.rows == camera.height) {
        frames.push_back(f.gray);
        stamps.push_back(f.t);
      }
    ReadoutEstimateOptions ro = opt.readout_estimate;
    ro.tracker = opt.tracker;
    if (opt.progress) ro.progress = [this](double f) { return opt.progress(f, "readout time"); };
    report.readout = calib::estimate_readout(rt, camera, stage2_extrinsics(report.roll_pitch.roll, report.roll_pitch.pitch),
                                             frames, stamps, ro);
    report.time.readout = seconds_since(t0);
    if (!report.readout.ok) return true;  // the camera's readout stays; the report says why
    const bool changed = report.readout.readout != camera.rolling_shutter_readout;
    camera.rolling_shutter_readout = report.readout.readout;
    if (!changed || !opt.estimate_roll_pitch) return true;
    const auto t1 = Clock::now();
    roll_pitch = estimator_on_held();
    report.time.roll_pitch += seconds_since(t1);
    if (!estimate_roll_pitch()) return false;
    // The tilt moved (a rolling shutter biases it): the readout once more from there.
    const auto t2 = Clock::now();
    ro.guess = report.readout.estimate;
    const ReadoutEstimate again = calib::estimate_readout(
        rt, camera, stage2_extrinsics(report.roll_pitch.roll, report.roll_pitch.pitch), frames, stamps, ro);
    report.time.readout += seconds_since(t2);
    if (!again.ok) return true;
    const int evaluations = report.readout.evaluations + again.evaluations;
    report.readout = again;
    report.readout.evaluations = evaluations;
    camera.rolling_shutter_readout = again.readout;
    return true;
  }

  // The hold ends: roll and pitch, the readout time, then the held frames are tracked.
  void end_hold() {
    if (roll_pitch && !estimate_roll_pitch()) return;
    if (estimating_readout && !estimate_readout()) return;
    roll_pitch.reset();  // its keyframe pyramids are no longer needed
    track_held();
    if (opt.estimate_roll_pitch && !tilt_held()) retry_until_tracking_holds();
    held.clear();
  }

  // Stage 2 from its start on the held frames (with stage 1's tilt), anything tracked before
  // forgotten.
  void track_held() {
    sampler.clear();
    report.tracking = {};
    frame_ms.clear();
    start_tracking();
    for (const HeldFrame& f : held) track(f.gray.data, f.gray.cols, f.gray.rows, f.gray.step, f.t, f.odometry, f.direction);
  }

  // Whether stage 2 kept most frames so far: a tilt it cannot hold is not the camera's
  // (tilt_not_held() says so at the end).
  bool tilt_held() const { return report.tracking.frames < 10 || 2 * report.tracking.lost <= report.tracking.frames; }

  // Stage 1 succeeded, but stage 2 lost most of the held frames with its tilt: stage 1 found a
  // wrong minimum. It runs again from the other starts, and a start is kept when stage 2 then
  // holds the held frames. Measured: a camera 8 cm high over black planks under its own lamp and
  // reflection, stage 1 30.8 deg off from straight down and from roll +0.4 rad, right from pitch
  // +-0.4 rad. When none holds, the first answer stands (tracked again; refused at the end).
  void retry_until_tracking_holds() {
    if (!try_other_starts([this] {
          track_held();
          return tilt_held();
        }))
      track_held();
  }

  void add_frame(const uint8_t* gray, int width, int height, size_t stride, double t,
                 const std::optional<SE2>& odometry, const std::optional<int>& direction) {
    if (!gray) throw_invalid_argument("calibration: the frame is null");
    if (width > 0 && stride < static_cast<size_t>(width))
      throw_invalid_argument("calibration: the frame's stride is less than its width");
    if (stage == Stage::Finished) throw_invalid_argument("calibration: frames added after finish()");
    if (stage == Stage::Stopped) return;
    if (stage == Stage::RollPitch) {
      const auto t0 = Clock::now();
      HeldFrame f;
      if (width == camera.width && height == camera.height)
        f.gray = cv::Mat(height, width, CV_8UC1, const_cast<uint8_t*>(gray), stride).clone();
      else
        f.gray = cv::Mat(height > 0 ? height : 1, width > 0 ? width : 1, CV_8UC1, cv::Scalar(0));  // tracked as lost
      f.t = t;
      f.odometry = odometry;
      f.direction = direction;
      held.push_back(std::move(f));
      if (roll_pitch && !roll_pitch_complete) roll_pitch_complete = roll_pitch->add_frame(gray, width, height, stride, t);
      report.time.roll_pitch += seconds_since(t0);
      const int n = static_cast<int>(held.size());
      const bool enough = (!roll_pitch || roll_pitch_complete) && (!estimating_readout || n >= opt.readout_frames);
      if (enough || n >= opt.max_buffered_frames) end_hold();
      return;
    }
    track(gray, width, height, stride, t, odometry, direction);
  }

  // Stage 3 and the composition.
  void calibrate_graph() {
    const auto t0 = Clock::now();
    graph::CalibrationOptions go = opt.graph;
    if (opt.initial) go.initial = std::array<double, 4>{opt.initial->x, opt.initial->y, opt.initial->z, opt.initial->yaw};
    std::vector<graph::MotionSample> samples;
    std::vector<Eigen::Matrix<double, 3, 2>> tilt_jacobians;
    for (size_t i = 0; i < sampler.samples().size(); ++i) {
      if (go.method == graph::CalibrationMethod::Odometry && !sampler.samples()[i].odometry) continue;
      samples.push_back(sampler.samples()[i]);
      tilt_jacobians.push_back(sampler.tilt_jacobians()[i]);
    }
    report.samples = samples;
    if (samples.size() < 3) {
      report.status = PipelineReport::Status::Failed;
      report.reason = "only " + std::to_string(samples.size()) + " frame intervals were tracked" +
                      (go.method == graph::CalibrationMethod::Odometry ? " with odometry" : "") +
                      ": nothing to calibrate x, y, height and yaw with";
      return;
    }
    report.graph = graph::calibrate(samples, go);
    report.time.graph = seconds_since(t0);
    const track::RollPitchResult& rp = report.roll_pitch;
    // The tilt's error moves every tracked motion alike: carried into the graph's parameters.
    std::optional<Eigen::Matrix<double, 4, 2>> J;
    if (propagate_tilt() && report.graph.summary.converged()) {
      const auto t1 = Clock::now();
      J = graph_tilt_jacobian(samples, tilt_jacobians, go, report.graph);
      report.time.tilt = seconds_since(t1);
    }
    report.tilt_jacobian = J;
    report.extrinsics =
        compose_extrinsics(rp.roll, rp.pitch, rp.covariance, opt.estimate_roll_pitch, report.graph, J ? &*J : nullptr);
    // The nonholonomic method takes a sample's label from its odometry where it has none (the
    // graph's rule); said in the method when no sample had a label of its own.
    const bool labels_from_odometry =
        go.method == graph::CalibrationMethod::Nonholonomic &&
        std::none_of(samples.begin(), samples.end(), [](const graph::MotionSample& s) { return s.direction.has_value(); }) &&
        std::any_of(samples.begin(), samples.end(), [](const graph::MotionSample& s) { return s.odometry.has_value(); });
    report.extrinsics.method = describe_camera_calibration(go.method, labels_from_odometry);
    if (const std::string why = tilt_not_held(); !why.empty()) {
      report.status = PipelineReport::Status::Failed;
      report.reason = why;
    } else if (report.graph.ok()) {
      report.status = PipelineReport::Status::Ok;
      report.reason.clear();
    } else if (!report.graph.unobservable_reason.empty()) {
      report.status = PipelineReport::Status::Unobservable;
      report.reason = report.graph.unobservable_reason;
    } else {
      report.status = PipelineReport::Status::Failed;
      report.reason = "the graph calibration did not converge: " + report.graph.summary.message;
    }
  }

  // Stage 2 tracks with stage 1's roll and pitch (or the given ones): when it loses most frames,
  // they do not describe the camera, and whatever the graph made of the intervals left is not the
  // camera's either. Measured (10-s 640x480 drive, a camera 8 cm high over black planks under its
  // own lamp and reflection): roll 30.8 deg and pitch 19.4 deg off, 234 of 300 frames lost, and a
  // result with sigmas of 0.06 deg written as if sound. "" when tracking held.
  std::string tilt_not_held() const {
    if (tilt_held()) return "";
    const PipelineReport::Tracking& k = report.tracking;
    char text[400];
    std::snprintf(text, sizeof text,
                  "tracking with the %s roll %.3f deg and pitch %.3f deg lost %d of %d frames: they do not "
                  "describe the camera%s",
                  opt.estimate_roll_pitch ? "estimated" : "given", report.roll_pitch.roll * 180 / M_PI,
                  report.roll_pitch.pitch * 180 / M_PI, k.lost, k.frames,
                  opt.estimate_roll_pitch
                      ? " (a reflection or the camera's own light over a dark floor can mislead their estimate; "
                        "a longer drive, or roll and pitch given, may help)"
                      : "");
    return text;
  }

  PipelineReport finish() {
    if (stage == Stage::Finished) throw_invalid_argument("calibration: finish() called twice");
    if (stage == Stage::RollPitch) end_hold();
    if (stage == Stage::Tracking) calibrate_graph();
    stage = Stage::Finished;
    if (!frame_ms.empty()) {
      std::vector<double> ms = frame_ms;
      std::nth_element(ms.begin(), ms.begin() + static_cast<long>(ms.size() / 2), ms.end());
      report.tracking.median_ms = ms[ms.size() / 2];
    }
    report.time.total = seconds_since(start);
    return std::move(report);
  }
};

CameraCalibrator::CameraCalibrator(ocl::Runtime& runtime, const CameraModel& camera, const PipelineOptions& options)
    : impl_(std::make_unique<Impl>(runtime, camera, options)) {}
CameraCalibrator::~CameraCalibrator() = default;
void CameraCalibrator::add_odometry(double timestamp, const SE2& pose) {
  std::vector<io::StampedPose>& s = impl_->odometry_samples;
  if (!std::isfinite(timestamp) || !std::isfinite(pose.x + pose.y + pose.theta))
    throw_invalid_argument("calibration: an odometry sample is not finite");
  if (!s.empty() && timestamp <= s.back().t)
    throw_invalid_argument("calibration: odometry at t = " + std::to_string(timestamp) +
                           " s is not after the sample before it (t = " + std::to_string(s.back().t) + " s)");
  s.push_back({timestamp, pose});
}

void CameraCalibrator::add_frame(const uint8_t* gray, int width, int height, size_t stride, double timestamp,
                                 const std::optional<SE2>& odometry_pose, const std::optional<int>& direction) {
  std::optional<SE2> pose = odometry_pose;
  std::vector<io::StampedPose>& s = impl_->odometry_samples;
  if (!pose && !s.empty()) {
    pose = io::interpolate_pose(s, timestamp);
    // Frames come in time order: the samples before the last one at or before this frame are done.
    const auto after = std::upper_bound(s.begin(), s.end(), timestamp,
                                        [](double t, const io::StampedPose& p) { return t < p.t; });
    if (after - s.begin() > 1) s.erase(s.begin(), after - 1);
  }
  impl_->add_frame(gray, width, height, stride, timestamp, pose, direction);
}
PipelineReport CameraCalibrator::finish() { return impl_->finish(); }
const char* CameraCalibrator::stage() const {
  switch (impl_->stage) {
    case Impl::Stage::RollPitch: return impl_->roll_pitch ? "roll and pitch" : "readout time";
    case Impl::Stage::Tracking: return "tracking";
    case Impl::Stage::Stopped: return "stopped";
    case Impl::Stage::Finished: return "finished";
  }
  return "?";
}

namespace {

// The loop calibrate_dataset and track_motions share: every frame of the data set in order, with
// the robot's odometry pose at its time and the direction label of the interval ending at it, to
// `add`; progress after each frame (the stage from `stage`), Cancelled when it says so. Returns
// the seconds spent waiting for images (io::Dataset decodes the next one while this one is used).
template <class Stage, class Add>
double drive(io::Dataset& ds, const std::function<bool(double, const char*)>& progress, Stage&& stage, Add&& add) {
  const int64_t n = ds.frame_count();
  double decode = 0.0;
  for (int64_t i = 0; i < n; ++i) {
    const auto d0 = Clock::now();
    const cv::Mat f = ds.frame(i);
    decode += seconds_since(d0);
    add(f, ds.timestamp(i), ds.odometry_at(i), ds.direction_for_interval(i));
    if (progress && !progress(static_cast<double>(i + 1) / static_cast<double>(n), stage()))
      throw Error(ErrorCode::Cancelled, "calibration cancelled");
  }
  return decode;
}

}  // namespace

PipelineReport calibrate_dataset(ocl::Runtime& runtime, io::Dataset& ds, const PipelineOptions& options) {
  const auto t0 = Clock::now();
  // The methods' inputs, checked here once for every caller (the C API, the command line).
  if (options.graph.method == graph::CalibrationMethod::Odometry && !ds.has_odometry())
    throw_invalid_input(ds.directory() + (ds.is_bag() ? ": no odometry topic given (--odom-topic, odometry_topic)" : " has no odometry.txt") +
                        ": the odometry method needs wheel odometry (or use the nonholonomic method with direction "
                        "labels and the camera height)");
  // Without labels the odometry's sign gives them (graph::CalibrationOptions::still_speed).
  if (options.graph.method == graph::CalibrationMethod::Nonholonomic && !ds.has_direction() && !ds.has_odometry())
    throw_invalid_input(ds.directory() +
                        (ds.is_bag() ? ": a bag has no direction labels, and no odometry topic was given (--odom-topic, "
                                       "odometry_topic) to take them from"
                                     : " has neither direction.txt nor odometry.txt") +
                        ": the nonholonomic method needs direction labels for y and the branch (the odometry's sign "
                        "gives them)");
  PipelineOptions o = options;
  if (o.readout == PipelineOptions::Readout::IfUnknown)
    o.readout = ds.readout_given() ? PipelineOptions::Readout::Off : PipelineOptions::Readout::On;
  CameraCalibrator calibrator(runtime, ds.camera(), o);
  const double decode = drive(
      ds, options.progress, [&] { return calibrator.stage(); },
      [&](const cv::Mat& f, double t, const std::optional<SE2>& odometry, const std::optional<int>& direction) {
        calibrator.add_frame(f.data, f.cols, f.rows, f.step, t, odometry, direction);
      });
  if (options.progress && !options.progress(1.0, "graph calibration")) throw Error(ErrorCode::Cancelled, "calibration cancelled");
  PipelineReport report = calibrator.finish();
  report.time.decode = decode;
  report.time.total = seconds_since(t0);
  return report;
}

std::vector<graph::MotionSample> track_motions(ocl::Runtime& runtime, io::Dataset& ds, const Extrinsics& extrinsics,
                                               const track::TrackerOptions& options,
                                               const std::function<bool(double, const char*)>& progress) {
  track::Tracker tracker(runtime, ds.camera(), extrinsics, options);
  MotionSampler sampler;
  drive(
      ds, progress, [] { return "tracking"; },
      [&](const cv::Mat& f, double t, const std::optional<SE2>& odometry, const std::optional<int>& direction) {
        sampler.add(tracker.track(f.data, f.cols, f.rows, f.step, t), t, odometry, direction);
      });
  return sampler.samples();
}

}  // namespace planarvo::calib
