// C API: the camera's calibration from images (src/calib/pipeline.h) and its first stage, roll and
// pitch from images (src/track/roll_pitch.h).
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "calib/motion_samples.h"
#include "calib/pipeline.h"
#include "capi/convert.h"
#include "capi/graph_convert.h"
#include "capi/handles.h"
#include "capi/status.h"
#include "capi/track_convert.h"
#include "core/error.h"
#include "core/sensor_motion.h"
#include "track/roll_pitch.h"

using planarvo::capi::guard;
using planarvo::capi::require;

struct planarvo_camera_calibrator {
  std::unique_ptr<planarvo::calib::CameraCalibrator> calibrator;
  cv::Mat grey;
  bool finished = false;
};

struct planarvo_roll_pitch {
  std::unique_ptr<planarvo::track::RollPitchEstimator> estimator;
  cv::Mat grey;  // conversion buffer for colour and float frames
};

namespace {

planarvo_calibration_status to_c(planarvo::track::RollPitchResult::Status s) {
  using S = planarvo::track::RollPitchResult::Status;
  switch (s) {
    case S::Ok: return PLANARVO_CALIBRATION_OK;
    case S::TooLittleTexture: return PLANARVO_CALIBRATION_TOO_LITTLE_TEXTURE;
    case S::TooLittleMotion: return PLANARVO_CALIBRATION_TOO_LITTLE_MOTION;
    case S::Failed: return PLANARVO_CALIBRATION_FAILED;
  }
  return PLANARVO_CALIBRATION_FAILED;
}

planarvo_calibration_status to_c(planarvo::calib::PipelineReport::Status s) {
  using S = planarvo::calib::PipelineReport::Status;
  switch (s) {
    case S::Ok: return PLANARVO_CALIBRATION_OK;
    case S::TooLittleTexture: return PLANARVO_CALIBRATION_TOO_LITTLE_TEXTURE;
    case S::TooLittleMotion: return PLANARVO_CALIBRATION_TOO_LITTLE_MOTION;
    case S::Unobservable: return PLANARVO_CALIBRATION_UNOBSERVABLE;
    case S::Failed: return PLANARVO_CALIBRATION_FAILED;
  }
  return PLANARVO_CALIBRATION_FAILED;
}

constexpr size_t kRollPitchOptionsEnd = offsetof(planarvo_roll_pitch_options, search) + sizeof(int32_t);
constexpr size_t kRollPitchResultEnd = offsetof(planarvo_roll_pitch_result, seconds) + sizeof(double);
constexpr size_t kCameraOptionsEnd =
    offsetof(planarvo_camera_calibration_options, progress_user_data) + sizeof(void*);
// Results this size and up receive the readout fields; older callers' structs end before them.
constexpr size_t kCameraResultEnd = offsetof(planarvo_camera_calibration_result, seconds_total) + sizeof(double);

planarvo::track::RollPitchOptions roll_pitch_options_from_c(const planarvo_roll_pitch_options* options) {
  planarvo_roll_pitch_options o;
  planarvo_roll_pitch_options_init(&o);
  if (options) {
    planarvo::capi::require_struct_size(options->struct_size, kRollPitchOptionsEnd, "planarvo_roll_pitch_options");
    o = planarvo::capi::read_versioned(*options, o);
  }
  require(std::isfinite(o.initial_roll) && std::isfinite(o.initial_pitch),
          "planarvo_roll_pitch_options.initial_roll and initial_pitch must be finite");
  require(o.max_frames >= 0, "planarvo_roll_pitch_options.max_frames must be >= 0");
  require(o.min_keyframes >= 2 && o.max_keyframes >= o.min_keyframes,
          "planarvo_roll_pitch_options: need 2 <= min_keyframes <= max_keyframes");
  require(o.keyframe_overlap > 0 && o.keyframe_overlap < 1, "planarvo_roll_pitch_options.keyframe_overlap must be in (0, 1)");
  planarvo::track::RollPitchOptions r;
  r.initial_roll = o.initial_roll;
  r.initial_pitch = o.initial_pitch;
  r.max_frames = o.max_frames;
  r.min_keyframes = o.min_keyframes;
  r.max_keyframes = o.max_keyframes;
  r.keyframe_overlap = o.keyframe_overlap;
  r.search = o.search != 0;
  return r;
}

planarvo_roll_pitch_result roll_pitch_result_to_c(const planarvo::track::RollPitchResult& r) {
  planarvo_roll_pitch_result out;
  std::memset(&out, 0, sizeof out);
  out.struct_size = sizeof out;
  out.status = to_c(r.status);
  planarvo::capi::copy_string(out.reason, sizeof out.reason, r.reason);
  out.roll = r.roll;
  out.pitch = r.pitch;
  planarvo::capi::matrix_to_c<2>(r.covariance, out.covariance);
  out.frames_used = r.frames_used;
  out.keyframes = r.keyframes;
  out.pairs = r.pairs;
  out.seconds = (r.track_ms + r.align_ms) / 1000.0;
  return out;
}

planarvo::CameraModel validated_camera(const planarvo_camera& camera, const char* where) {
  const planarvo::CameraModel cam = planarvo::capi::to_cpp(camera);
  try {
    cam.validate(where);
  } catch (const planarvo::Error& e) {
    throw planarvo::Error(planarvo::ErrorCode::InvalidArgument, e.what());
  }
  return cam;
}

planarvo::calib::PipelineOptions pipeline_options_from_c(const planarvo_camera_calibration_options* options) {
  planarvo_camera_calibration_options o;
  planarvo_camera_calibration_options_init(&o);
  if (options) {
    planarvo::capi::require_struct_size(options->struct_size, kCameraOptionsEnd, "planarvo_camera_calibration_options");
    o = planarvo::capi::read_versioned(*options, o);
  }
  const int method = planarvo::capi::enum_value(o.method);
  require(method == PLANARVO_CALIBRATE_ODOMETRY || method == PLANARVO_CALIBRATE_NONHOLONOMIC,
          "planarvo_camera_calibration_options.method is not a planarvo_calibration_method");
  require(std::isfinite(o.height) && o.height >= 0, "planarvo_camera_calibration_options.height must be >= 0");
  require(o.roll_pitch_frames >= 0, "planarvo_camera_calibration_options.roll_pitch_frames must be >= 0");
  planarvo::calib::PipelineOptions po;
  planarvo_calibration_options graph_read;
  if (o.graph)
    po.graph = planarvo::capi::calibration_options_from_c(
        o.graph, &graph_read, planarvo::calib::PipelineOptions::default_graph_options().estimate_odometry_noise);
  po.graph.method = o.method == PLANARVO_CALIBRATE_ODOMETRY ? planarvo::graph::CalibrationMethod::Odometry
                                                            : planarvo::graph::CalibrationMethod::Nonholonomic;
  po.graph.fix_scale = o.height > 0;
  po.graph.fixed_scale = o.height > 0 ? o.height : 1.0;
  if (o.tracker) po.tracker = planarvo::capi::tracker_options_from_c(o.tracker);
  po.roll_pitch.max_frames = o.roll_pitch_frames;
  po.estimate_roll_pitch = o.estimate_roll_pitch != 0;
  po.accept_unusual_extrinsics = o.accept_unusual_extrinsics != 0;
  const int readout = planarvo::capi::enum_value(o.readout);
  require(readout >= PLANARVO_READOUT_IF_UNKNOWN && readout <= PLANARVO_READOUT_ESTIMATE,
          "planarvo_camera_calibration_options.readout is not a planarvo_readout_source");
  po.readout = readout == PLANARVO_READOUT_CAMERA     ? planarvo::calib::PipelineOptions::Readout::Off
               : readout == PLANARVO_READOUT_ESTIMATE ? planarvo::calib::PipelineOptions::Readout::On
                                                      : planarvo::calib::PipelineOptions::Readout::IfUnknown;
  if (o.has_initial) {
    po.initial = planarvo::capi::to_cpp(o.initial);
    require(po.initial->z > 0 && po.initial->finite(),
            "planarvo_camera_calibration_options.initial must be finite with z > 0");
  }
  if (o.progress) {
    const planarvo_progress_fn fn = o.progress;
    void* user = o.progress_user_data;
    po.progress = [fn, user](double f, const char* stage) { return fn(user, f, stage) == 0; };
  }
  return po;
}

planarvo_camera_calibration_result report_to_c(const planarvo::calib::PipelineReport& r) {
  planarvo_camera_calibration_result out;
  std::memset(&out, 0, sizeof out);
  out.struct_size = sizeof out;
  out.status = to_c(r.status);
  planarvo::capi::copy_string(out.reason, sizeof out.reason, r.reason);
  out.extrinsics = planarvo::capi::to_c(r.extrinsics.value);
  planarvo::capi::matrix_to_c<6>(r.extrinsics.covariance, out.covariance);
  for (size_t i = 0; i < 6; ++i) {
    out.estimated[i] = r.extrinsics.estimated[i];
    out.observable[i] = r.extrinsics.observable[i];
  }
  out.roll_pitch = roll_pitch_result_to_c(r.roll_pitch);
  out.graph = planarvo::capi::calibration_result_to_c(r.graph);
  out.graph.struct_size = sizeof out.graph;
  out.frames = r.tracking.frames;
  out.frames_ok = r.tracking.ok;
  out.frames_degraded = r.tracking.degraded;
  out.frames_lost = r.tracking.lost;
  out.samples = static_cast<int32_t>(r.samples.size());
  out.tracking_median_ms = r.tracking.median_ms;
  out.seconds_decode = r.time.decode;
  out.seconds_roll_pitch = r.time.roll_pitch;
  out.seconds_tracking = r.time.tracking;
  out.seconds_graph = r.time.graph;
  out.seconds_total = r.time.total;
  out.readout = r.readout_used;
  out.readout_estimate = r.readout.estimate;
  out.readout_sigma = r.readout.sigma;
  out.readout_evaluations = r.readout.evaluations;
  out.readout_frames = r.readout.frames;
  planarvo::capi::copy_string(out.readout_reason, sizeof out.readout_reason, r.readout.reason);
  out.seconds_readout = r.time.readout;
  planarvo::capi::copy_string(out.method, sizeof out.method, r.extrinsics.method);
  return out;
}

}  // namespace

extern "C" {

PLANARVO_API void planarvo_roll_pitch_options_init(planarvo_roll_pitch_options* o) {
  if (!o) return;
  std::memset(o, 0, sizeof *o);
  const planarvo::track::RollPitchOptions d;
  o->struct_size = sizeof *o;
  o->initial_roll = d.initial_roll;
  o->initial_pitch = d.initial_pitch;
  o->max_frames = d.max_frames;
  o->min_keyframes = d.min_keyframes;
  o->max_keyframes = d.max_keyframes;
  o->keyframe_overlap = d.keyframe_overlap;
  o->search = d.search ? 1 : 0;
}

PLANARVO_API planarvo_status planarvo_roll_pitch_create(planarvo_context* context, const planarvo_camera* camera,
                                                        const planarvo_roll_pitch_options* options,
                                                        planarvo_roll_pitch** estimator) {
  return guard([&] {
    require(estimator != nullptr, "planarvo_roll_pitch_create: estimator is NULL");
    *estimator = nullptr;
    require(context != nullptr && camera != nullptr, "planarvo_roll_pitch_create: context and camera are required");
    const planarvo::CameraModel cam = validated_camera(*camera, "planarvo_roll_pitch_create: camera");
    auto h = std::make_unique<planarvo_roll_pitch>();
    h->estimator = std::make_unique<planarvo::track::RollPitchEstimator>(*context->runtime, cam,
                                                                         roll_pitch_options_from_c(options));
    *estimator = h.release();
  });
}

PLANARVO_API void planarvo_roll_pitch_destroy(planarvo_roll_pitch* estimator) { delete estimator; }

PLANARVO_API planarvo_status planarvo_roll_pitch_add_frame(planarvo_roll_pitch* estimator,
                                                           const planarvo_image* image, double timestamp,
                                                           int32_t* complete) {
  return guard([&] {
    require(estimator != nullptr && image != nullptr, "planarvo_roll_pitch_add_frame: NULL argument");
    require(image->data != nullptr && image->width > 0 && image->height > 0,
            "planarvo_roll_pitch_add_frame: the image has no pixels");
    require(planarvo::capi::enum_value(image->format) >= PLANARVO_GRAY8 &&
                planarvo::capi::enum_value(image->format) <= PLANARVO_GRAY32F,
            "planarvo_roll_pitch_add_frame: unknown pixel format");
    size_t stride = 0;
    const uint8_t* grey =
        planarvo::capi::grey_view(*image, estimator->grey, &stride, "planarvo_roll_pitch_add_frame");
    const bool done = estimator->estimator->add_frame(grey, image->width, image->height, stride, timestamp);
    if (complete) *complete = done ? 1 : 0;
  });
}

PLANARVO_API planarvo_status planarvo_roll_pitch_estimate(planarvo_roll_pitch* estimator,
                                                          planarvo_roll_pitch_result* result) {
  std::string reason;
  const planarvo_status st = guard([&] {
    require(estimator != nullptr && result != nullptr, "planarvo_roll_pitch_estimate: NULL argument");
    planarvo::capi::require_struct_size(result->struct_size, kRollPitchResultEnd, "planarvo_roll_pitch_result");
    const planarvo::track::RollPitchResult r = estimator->estimator->estimate();
    planarvo::capi::write_versioned(roll_pitch_result_to_c(r), result);
    reason = r.reason;
  });
  if (st == PLANARVO_OK && !reason.empty()) return planarvo::capi::fail(PLANARVO_ERROR_FAILED, reason);
  return st;
}

PLANARVO_API void planarvo_camera_calibration_options_init(planarvo_camera_calibration_options* o) {
  if (!o) return;
  std::memset(o, 0, sizeof *o);
  o->struct_size = sizeof *o;
  o->method = PLANARVO_CALIBRATE_ODOMETRY;
  o->height = 0.0;
  o->roll_pitch_frames = 0;
  o->estimate_roll_pitch = 1;
  o->readout = PLANARVO_READOUT_CAMERA;
}

PLANARVO_API planarvo_status planarvo_calibrate_dataset(planarvo_context* context, planarvo_dataset* dataset,
                                                        const planarvo_camera_calibration_options* options,
                                                        planarvo_camera_calibration_result* result) {
  std::string reason;
  const planarvo_status st = guard([&] {
    require(context != nullptr && dataset != nullptr && result != nullptr, "planarvo_calibrate_dataset: NULL argument");
    planarvo::capi::require_struct_size(result->struct_size, kCameraResultEnd, "planarvo_camera_calibration_result");
    const planarvo::calib::PipelineOptions po = pipeline_options_from_c(options);
    const planarvo::calib::PipelineReport r = planarvo::calib::calibrate_dataset(*context->runtime, *dataset->dataset, po);

    const planarvo_camera_calibration_result out = report_to_c(r);
    planarvo::capi::write_versioned(out, result);
    reason = r.reason;
    if (!r.ok() && reason.empty()) reason = planarvo::calib::status_name(r.status);
  });
  if (st == PLANARVO_OK && !reason.empty()) return planarvo::capi::fail(PLANARVO_ERROR_FAILED, reason);
  return st;
}

PLANARVO_API planarvo_status planarvo_camera_calibrator_create(planarvo_context* context,
                                                               const planarvo_camera* camera,
                                                               const planarvo_camera_calibration_options* options,
                                                               planarvo_camera_calibrator** calibrator) {
  return guard([&] {
    require(calibrator != nullptr, "planarvo_camera_calibrator_create: calibrator is NULL");
    *calibrator = nullptr;
    require(context != nullptr && camera != nullptr, "planarvo_camera_calibrator_create: context and camera are required");
    const planarvo::CameraModel cam = validated_camera(*camera, "planarvo_camera_calibrator_create: camera");
    auto h = std::make_unique<planarvo_camera_calibrator>();
    h->calibrator = std::make_unique<planarvo::calib::CameraCalibrator>(*context->runtime, cam,
                                                                        pipeline_options_from_c(options));
    *calibrator = h.release();
  });
}

PLANARVO_API void planarvo_camera_calibrator_destroy(planarvo_camera_calibrator* calibrator) { delete calibrator; }

PLANARVO_API planarvo_status planarvo_camera_calibrator_add_frame(planarvo_camera_calibrator* calibrator,
                                                                  const planarvo_image* image, double timestamp,
                                                                  const planarvo_se2* odometry_pose,
                                                                  const int32_t* direction) {
  return guard([&] {
    require(calibrator != nullptr && image != nullptr, "planarvo_camera_calibrator_add_frame: NULL argument");
    require(!calibrator->finished, "planarvo_camera_calibrator_add_frame: the calibrator has finished");
    require(image->data != nullptr && image->width > 0 && image->height > 0,
            "planarvo_camera_calibrator_add_frame: the image has no pixels");
    require(planarvo::capi::enum_value(image->format) >= PLANARVO_GRAY8 &&
                planarvo::capi::enum_value(image->format) <= PLANARVO_GRAY32F,
            "planarvo_camera_calibrator_add_frame: unknown pixel format");
    require(std::isfinite(timestamp), "planarvo_camera_calibrator_add_frame: timestamp is not finite");
    require(!direction || (*direction >= -1 && *direction <= 1),
            "planarvo_camera_calibrator_add_frame: direction must be -1, 0 or 1");
    require(!odometry_pose || std::isfinite(odometry_pose->x + odometry_pose->y + odometry_pose->theta),
            "planarvo_camera_calibrator_add_frame: odometry_pose is not finite");
    size_t stride = 0;
    const uint8_t* grey =
        planarvo::capi::grey_view(*image, calibrator->grey, &stride, "planarvo_camera_calibrator_add_frame");
    std::optional<planarvo::SE2> odometry;
    if (odometry_pose) odometry = planarvo::capi::to_cpp(*odometry_pose);
    std::optional<int> label;
    if (direction) label = *direction;
    calibrator->calibrator->add_frame(grey, image->width, image->height, stride, timestamp, odometry, label);
  });
}

PLANARVO_API planarvo_status planarvo_camera_calibrator_add_odometry(planarvo_camera_calibrator* calibrator,
                                                                     double timestamp, const planarvo_se2* pose) {
  return guard([&] {
    require(calibrator != nullptr && pose != nullptr, "planarvo_camera_calibrator_add_odometry: NULL argument");
    require(!calibrator->finished, "planarvo_camera_calibrator_add_odometry: the calibrator has finished");
    calibrator->calibrator->add_odometry(timestamp, planarvo::capi::to_cpp(*pose));
  });
}

PLANARVO_API planarvo_status planarvo_camera_calibrator_finish(planarvo_camera_calibrator* calibrator,
                                                               planarvo_camera_calibration_result* result) {
  std::string reason;
  const planarvo_status st = guard([&] {
    require(calibrator != nullptr && result != nullptr, "planarvo_camera_calibrator_finish: NULL argument");
    planarvo::capi::require_struct_size(result->struct_size, kCameraResultEnd, "planarvo_camera_calibration_result");
    require(!calibrator->finished, "planarvo_camera_calibrator_finish: called twice");
    calibrator->finished = true;
    const planarvo::calib::PipelineReport r = calibrator->calibrator->finish();
    planarvo::capi::write_versioned(report_to_c(r), result);
    reason = r.reason;
    if (!r.ok() && reason.empty()) reason = planarvo::calib::status_name(r.status);
  });
  if (st == PLANARVO_OK && !reason.empty()) return planarvo::capi::fail(PLANARVO_ERROR_FAILED, reason);
  return st;
}

PLANARVO_API planarvo_status planarvo_track_motions(planarvo_context* context, planarvo_dataset* dataset,
                                                    const planarvo_extrinsics* extrinsics,
                                                    const planarvo_tracker_options* options,
                                                    planarvo_motion_pair* pairs, size_t capacity, size_t* count) {
  return guard([&] {
    require(context != nullptr && dataset != nullptr && extrinsics != nullptr && pairs != nullptr && count != nullptr,
            "planarvo_track_motions: NULL argument");
    *count = 0;
    planarvo::io::Dataset& ds = *dataset->dataset;
    const auto n = static_cast<size_t>(ds.frame_count());
    if (capacity + 1 < n)
      throw planarvo::capi::BufferTooSmall("planarvo_track_motions: " + std::to_string(n) + " frames need capacity " +
                                           std::to_string(n - 1) + ", not " + std::to_string(capacity));
    const planarvo::Extrinsics e = planarvo::capi::to_cpp(*extrinsics);
    const std::vector<planarvo::graph::MotionSample> samples = planarvo::calib::track_motions(
        *context->runtime, ds, e, planarvo::capi::tracker_options_from_c(options));
    for (const planarvo::graph::MotionSample& s : samples) {
      planarvo_motion_pair p;
      planarvo_motion_pair_init(&p);
      p.interval = s.interval;
      // The camera's own motion, whatever extrinsics tracked it (the tracked motion itself at
      // x = y = 0, z = 1, yaw = 0): pairs that calibrate correctly, as track --motions-out writes.
      planarvo::capi::motion_to_c(planarvo::sensor_motion(e, s.sensor), &p.sensor, &p.has_sensor_covariance,
                                  p.sensor_covariance);
      p.has_odometry = s.odometry.has_value();
      if (s.odometry) planarvo::capi::motion_to_c(*s.odometry, &p.odometry, &p.has_odometry_covariance, p.odometry_covariance);
      p.has_direction = s.direction.has_value();
      if (s.direction) p.direction = *s.direction;
      pairs[(*count)++] = p;
    }
  });
}

PLANARVO_API planarvo_status planarvo_compose_extrinsics(double roll, double pitch,
                                                         const double* roll_pitch_covariance,
                                                         const planarvo_calibration_result* graph,
                                                         planarvo_extrinsics* extrinsics, double* covariance,
                                                         int32_t* estimated) {
  return guard([&] {
    require(graph != nullptr, "planarvo_compose_extrinsics: graph is NULL");
    require(std::isfinite(roll) && std::isfinite(pitch), "planarvo_compose_extrinsics: roll and pitch must be finite");
    planarvo::graph::CalibrationResult g;
    for (size_t i = 0; i < 4; ++i) {
      g.value[i] = graph->value[i];
      g.estimated[i] = graph->estimated[i] != 0;
      g.observable[i] = graph->observable[i] != 0;
    }
    g.covariance = planarvo::capi::matrix_from_c<4>(graph->covariance);
    const Eigen::Matrix2d rp = roll_pitch_covariance ? Eigen::Matrix2d(planarvo::capi::matrix_from_c<2>(roll_pitch_covariance))
                                                     : Eigen::Matrix2d(Eigen::Matrix2d::Zero());
    const planarvo::ExtrinsicsEstimate e =
        planarvo::calib::compose_extrinsics(roll, pitch, rp, roll_pitch_covariance != nullptr, g);
    if (extrinsics) *extrinsics = planarvo::capi::to_c(e.value);
    if (covariance) planarvo::capi::matrix_to_c<6>(e.covariance, covariance);
    if (estimated)
      for (size_t i = 0; i < 6; ++i) estimated[i] = e.estimated[i] ? 1 : 0;
  });
}

}  // extern "C"
