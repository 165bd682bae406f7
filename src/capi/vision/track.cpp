// C API: visual odometry (src/track/tracker.h) and the accuracy of motions.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "capi/convert.h"
#include "capi/track_convert.h"
#include "capi/handles.h"
#include "capi/status.h"
#include "core/error.h"
#include "track/evaluation.h"
#include "track/body_lean.h"
#include "track/tracker.h"

using planarvo::capi::guard;
using planarvo::capi::require;

struct planarvo_tracker {
  std::unique_ptr<planarvo::track::Tracker> tracker;
  planarvo::CameraModel camera;  // the distorted camera, for saving the flat field
  cv::Mat grey;  // conversion buffer for colour and float frames
};

namespace {

planarvo_track_status to_c(planarvo::track::FrameResult::Status s) {
  using S = planarvo::track::FrameResult::Status;
  switch (s) {
    case S::First: return PLANARVO_TRACK_FIRST;
    case S::Ok: return PLANARVO_TRACK_OK;
    case S::Degraded: return PLANARVO_TRACK_DEGRADED;
    case S::Lost: return PLANARVO_TRACK_LOST;
  }
  return PLANARVO_TRACK_LOST;
}

}  // namespace

namespace planarvo::capi {

// The frame as 8-bit grey: a view of the caller's memory when it already is, else converted.
const uint8_t* grey_view(const planarvo_image& im, cv::Mat& buffer, size_t* stride, const char* function) {
  const size_t bpp = im.format == PLANARVO_GRAY8 ? 1 : im.format == PLANARVO_GRAY32F ? 4 : 3;
  // Checked here for every caller: a colour or float stride below the row was an OpenCV
  // assertion (PLANARVO_ERROR_INTERNAL) in planarvo_roll_pitch_add_frame and
  // planarvo_camera_calibrator_add_frame, found by fuzzing.
  require(im.stride >= bpp * static_cast<size_t>(im.width),
          (std::string(function) + ": stride is less than the row (width x bytes per pixel)").c_str());
  // OpenCV asserts on a float image whose rows are not whole floats apart (also found by fuzzing).
  require(im.stride % (bpp == 4 ? 4 : 1) == 0,
          (std::string(function) + ": stride of a PLANARVO_GRAY32F image must be a multiple of 4").c_str());
  const int type = im.format == PLANARVO_GRAY8 ? CV_8UC1
                   : im.format == PLANARVO_GRAY32F ? CV_32FC1
                                                   : CV_8UC3;
  const cv::Mat src(im.height, im.width, type, const_cast<void*>(im.data), im.stride);
  switch (im.format) {
    case PLANARVO_GRAY8:
      *stride = im.stride;
      return static_cast<const uint8_t*>(im.data);
    case PLANARVO_BGR8: cv::cvtColor(src, buffer, cv::COLOR_BGR2GRAY); break;
    case PLANARVO_RGB8: cv::cvtColor(src, buffer, cv::COLOR_RGB2GRAY); break;
    case PLANARVO_GRAY32F: src.convertTo(buffer, CV_8UC1); break;  // rounds and saturates
  }
  *stride = buffer.step[0];
  return buffer.data;
}


planarvo::track::TrackerOptions tracker_options_from_c(const planarvo_tracker_options* options) {
  planarvo::track::TrackerOptions o;
  if (options) {
    planarvo::capi::require_struct_size(options->struct_size,
                                        offsetof(planarvo_tracker_options, estimate_brightness) + 4,
                                        "planarvo_tracker_options");
    require(options->levels >= 1 && options->levels <= planarvo::track::kMaxLevels,
            "planarvo_tracker_options.levels must be 1..8");
    require(options->finest_level >= -1 && options->finest_level < options->levels,
            "planarvo_tracker_options.finest_level must be -1 (automatic) or 0..levels-1");
    require(options->max_iterations >= 0, "planarvo_tracker_options.max_iterations must be >= 0");
    require(options->keyframe_overlap > 0 && options->keyframe_overlap < 1,
            "planarvo_tracker_options.keyframe_overlap must be in (0, 1)");
    o.levels = options->levels;
    o.finest_level = options->finest_level;
    if (options->max_iterations > 0)
      for (int& n : o.max_iterations) n = std::min(n, static_cast<int>(options->max_iterations));
    o.keyframe_overlap = options->keyframe_overlap;
    o.estimate_brightness = options->estimate_brightness != 0;
    if (options->struct_size >= offsetof(planarvo_tracker_options, level0_subsample) + sizeof(int32_t)) {
      require(options->level0_subsample >= 0 && options->level0_subsample <= 8,
              "planarvo_tracker_options.level0_subsample must be 0..8");
      const int b = options->level0_subsample;
      if (o.finest_level < 0) {
        if (b > 0) o.auto_finer_block = b;  // 0: the default's 3
      } else {
        o.select_blocks[static_cast<size_t>(o.finest_level)] = b >= 2 ? b : 0;
      }
    }
    if (options->struct_size >= offsetof(planarvo_tracker_options, flat_field) + sizeof(const char*) &&
        options->flat_field)
      o.flat_field = options->flat_field;
    if (options->struct_size >= offsetof(planarvo_tracker_options, local_plane_prior_sigma) + sizeof(double)) {
      o.local_plane = options->local_plane != 0;
      require(std::isfinite(options->local_plane_prior_sigma) && options->local_plane_prior_sigma > 0,
              "planarvo_tracker_options.local_plane_prior_sigma must be a positive, finite number of radians");
      o.local_plane_prior_sigma = options->local_plane_prior_sigma;
    }
    if (options->struct_size >= offsetof(planarvo_tracker_options, mounting_min_step) + sizeof(double)) {
      using Response = planarvo::track::TrackerOptions::MountingResponse;
      switch (options->on_mounting_change) {
        case PLANARVO_MOUNTING_IGNORE: o.on_mounting_change = Response::Ignore; break;
        case PLANARVO_MOUNTING_REPORT: o.on_mounting_change = Response::Report; break;
        case PLANARVO_MOUNTING_RECALIBRATE: o.on_mounting_change = Response::Recalibrate; break;
        default:
          planarvo::throw_invalid_argument(
              "planarvo_tracker_options.on_mounting_change must be PLANARVO_MOUNTING_IGNORE, _REPORT or _RECALIBRATE");
      }
      require(std::isfinite(options->mounting_min_step) && options->mounting_min_step > 0,
              "planarvo_tracker_options.mounting_min_step must be a positive, finite number of radians");
      o.mounting_watch.min_step = options->mounting_min_step;
    }
    if (options->struct_size >= offsetof(planarvo_tracker_options, accept_unusual_extrinsics) + sizeof(int32_t))
      o.accept_unusual_extrinsics = options->accept_unusual_extrinsics != 0;
  }
  return o;
}

}  // namespace planarvo::capi

extern "C" {

PLANARVO_API void planarvo_tracker_options_init(planarvo_tracker_options* o) {
  if (!o) return;
  std::memset(o, 0, sizeof *o);
  const planarvo::track::TrackerOptions d;
  o->struct_size = sizeof *o;
  o->levels = d.levels;
  o->finest_level = d.finest_level;
  o->max_iterations = 0;
  o->keyframe_overlap = d.keyframe_overlap;
  o->estimate_brightness = d.estimate_brightness ? 1 : 0;
  o->local_plane = d.local_plane ? 1 : 0;
  o->local_plane_prior_sigma = d.local_plane_prior_sigma;
  using Response = planarvo::track::TrackerOptions::MountingResponse;
  o->on_mounting_change = d.on_mounting_change == Response::Ignore   ? PLANARVO_MOUNTING_IGNORE
                          : d.on_mounting_change == Response::Report ? PLANARVO_MOUNTING_REPORT
                                                                     : PLANARVO_MOUNTING_RECALIBRATE;
  o->mounting_min_step = d.mounting_watch.min_step;
}

PLANARVO_API planarvo_status planarvo_tracker_create(planarvo_context* context, const planarvo_camera* camera,
                                                     const planarvo_extrinsics* extrinsics,
                                                     const planarvo_tracker_options* options,
                                                     planarvo_tracker** tracker) {
  return guard([&] {
    require(tracker != nullptr, "planarvo_tracker_create: tracker is NULL");
    *tracker = nullptr;
    require(context != nullptr && camera != nullptr && extrinsics != nullptr,
            "planarvo_tracker_create: context, camera and extrinsics are required");
    const planarvo::CameraModel cam = planarvo::capi::to_cpp(*camera);
    try {
      cam.validate("planarvo_tracker_create: camera");
    } catch (const planarvo::Error& e) {
      throw planarvo::Error(planarvo::ErrorCode::InvalidArgument, e.what());
    }
    require(extrinsics->z > 0, "planarvo_tracker_create: extrinsics.z (the camera height) must be positive");
    const planarvo::track::TrackerOptions o = planarvo::capi::tracker_options_from_c(options);
    auto t = std::make_unique<planarvo_tracker>();
    t->camera = cam;
    t->tracker = std::make_unique<planarvo::track::Tracker>(*context->runtime, cam,
                                                            planarvo::capi::to_cpp(*extrinsics), o);
    *tracker = t.release();
  });
}

PLANARVO_API void planarvo_tracker_destroy(planarvo_tracker* tracker) { delete tracker; }

PLANARVO_API planarvo_status planarvo_tracker_track(planarvo_tracker* tracker, const planarvo_image* image,
                                                    double timestamp, planarvo_track_result* result) {
  return guard([&] {
    require(tracker != nullptr && image != nullptr && result != nullptr, "planarvo_tracker_track: NULL argument");
    planarvo::capi::require_struct_size(result->struct_size, offsetof(planarvo_track_result, ms) + sizeof(double),
                                        "planarvo_track_result");
    require(image->data != nullptr && image->width > 0 && image->height > 0,
            "planarvo_tracker_track: the image has no pixels");
    require(planarvo::capi::enum_value(image->format) >= PLANARVO_GRAY8 &&
                planarvo::capi::enum_value(image->format) <= PLANARVO_GRAY32F,
            "planarvo_tracker_track: unknown pixel format");
    const size_t bpp = image->format == PLANARVO_GRAY8 ? 1 : image->format == PLANARVO_GRAY32F ? 4 : 3;
    require(image->stride >= bpp * static_cast<size_t>(image->width), "planarvo_tracker_track: stride < row size");
    require(std::isfinite(timestamp), "planarvo_tracker_track: timestamp is NaN or inf");
    size_t stride = 0;
    const uint8_t* grey = planarvo::capi::grey_view(*image, tracker->grey, &stride, "planarvo_tracker_track");
    const planarvo::track::FrameResult r =
        tracker->tracker->track(grey, image->width, image->height, stride, timestamp);
    planarvo_track_result out;
    std::memset(&out, 0, sizeof out);
    out.struct_size = result->struct_size;
    out.status = to_c(r.status);
    out.reason = r.reason;
    out.motion = planarvo::capi::to_c(r.motion.value);
    planarvo::capi::matrix_to_c<3>(r.motion.covariance, out.covariance);
    out.pose = planarvo::capi::to_c(tracker->tracker->pose());
    for (int i = 0; i < 8; ++i) out.iterations[i] = r.iterations[static_cast<size_t>(i)];
    out.levels_used = r.levels_used;
    out.final_cost = r.final_cost;
    out.inlier_fraction = r.inlier_fraction;
    out.overlap = r.overlap;
    out.keyframe = r.keyframe ? 1 : 0;
    out.ms = r.ms;
    out.roll = r.attitude.roll;
    out.pitch = r.attitude.pitch;
    planarvo::capi::matrix_to_c<2>(r.attitude_covariance, out.attitude_covariance);
    out.mounting = planarvo::capi::to_c(r.mounting);
    out.attitude_observed = r.attitude_observed ? 1 : 0;
    out.mounting_changed = r.mounting_changed ? 1 : 0;
    if (r.mounting_changed) {
      out.mounting_refinement = r.mounting_change.refinement ? 1 : 0;
      out.mounting_change_time = r.mounting_change.time;
      out.mounting_step[0] = r.mounting_change.step.roll;
      out.mounting_step[1] = r.mounting_change.step.pitch;
      out.mounting_step_sigma[0] = r.mounting_change.sigma(0);
      out.mounting_step_sigma[1] = r.mounting_change.sigma(1);
      out.mounting_step[2] = r.mounting_change.dyaw;
      out.mounting_step_sigma[2] = r.mounting_change.sigma_yaw;
      out.mounting_step[3] = r.mounting_change.dz;
      out.mounting_step_sigma[3] = r.mounting_change.sigma_z;
      out.changed_mounting = planarvo::capi::to_c(r.changed_mounting);
    }
    std::memcpy(result, &out, std::min(result->struct_size, sizeof out));
  });
}

PLANARVO_API planarvo_status planarvo_tracker_odometry(planarvo_tracker* tracker, const planarvo_se2* pose) {
  return guard([&] {
    require(tracker != nullptr && pose != nullptr, "planarvo_tracker_odometry: NULL argument");
    require(std::isfinite(pose->x + pose->y + pose->theta), "planarvo_tracker_odometry: the pose is not finite");
    tracker->tracker->set_odometry(planarvo::capi::to_cpp(*pose));
  });
}

PLANARVO_API planarvo_status planarvo_tracker_reset(planarvo_tracker* tracker) {
  return guard([&] {
    require(tracker != nullptr, "planarvo_tracker_reset: tracker is NULL");
    tracker->tracker->reset();
  });
}

PLANARVO_API planarvo_status planarvo_tracker_save_flat_field(planarvo_tracker* tracker, const char* path) {
  return guard([&] {
    require(tracker != nullptr && path != nullptr && path[0] != '\0',
            "planarvo_tracker_save_flat_field: tracker and path are required");
    const planarvo::PhotometricFit* fit = tracker->tracker->photometric_model();
    if (!fit)
      throw planarvo::Error(planarvo::ErrorCode::Failed,
                            "planarvo_tracker_save_flat_field: no photometric model has been learnt yet (it stays the "
                            "identity until enough frames in motion show light fixed to the camera, or the "
                            "photometric model is off); " + std::string(path) + " is not written");
    planarvo::write_flat_field(path, planarvo::fill_flat_field(planarvo::flat_field_to_distorted(*fit, tracker->camera)));
  });
}

PLANARVO_API planarvo_status planarvo_tracker_residuals(planarvo_tracker* tracker, int32_t level, float* residual,
                                                        float* weight, float* intensity, size_t capacity,
                                                        int32_t* width, int32_t* height, double* threshold) {
  return guard([&] {
    require(tracker != nullptr, "planarvo_tracker_residuals: tracker is NULL");
    require(level >= 0 && level < planarvo::track::kMaxLevels, "planarvo_tracker_residuals: level must be 0..7");
    const planarvo::track::ResidualImage r = tracker->tracker->residuals(level);
    const size_t n = static_cast<size_t>(r.width) * static_cast<size_t>(r.height);
    if (width) *width = r.width;
    if (height) *height = r.height;
    if (threshold) *threshold = r.huber_k;
    if ((residual || weight || intensity) && capacity < n)
      throw planarvo::capi::BufferTooSmall("planarvo_tracker_residuals: capacity " + std::to_string(capacity) +
                                           " is less than width x height = " + std::to_string(n));
    if (residual) std::copy(r.residual.begin(), r.residual.end(), residual);
    if (weight) std::copy(r.weight.begin(), r.weight.end(), weight);
    if (intensity) std::copy(r.intensity.begin(), r.intensity.end(), intensity);
  });
}

namespace {
planarvo_line_fit line_to_c(const planarvo::track::LineFit& f) {
  return planarvo_line_fit{f.slope, f.offset, f.slope_sigma, f.r2, f.samples};
}
}  // namespace

PLANARVO_API planarvo_status planarvo_fit_body_lean(const double* timestamps, const planarvo_se2* motions,
                                                    const double* roll, const double* pitch, const int32_t* use,
                                                    size_t count, planarvo_body_lean* lean) {
  return guard([&] {
    require(lean != nullptr, "planarvo_fit_body_lean: lean is NULL");
    planarvo::capi::require_struct_size(lean->struct_size, sizeof(planarvo_body_lean), "planarvo_body_lean");
    require(count == 0 || (timestamps && motions && roll && pitch), "planarvo_fit_body_lean: NULL arrays");
    std::vector<double> t(timestamps, timestamps + count), r(roll, roll + count), p(pitch, pitch + count);
    std::vector<planarvo::SE2> m(count);
    std::vector<bool> u(count, true);
    for (size_t i = 0; i < count; ++i) {
      m[i] = planarvo::capi::to_cpp(motions[i]);
      if (use) u[i] = use[i] != 0;
    }
    const planarvo::track::BodyLean f = planarvo::track::fit_body_lean(t, m, r, p, u);
    lean->roll_per_yaw_rate = line_to_c(f.roll_per_yaw_rate);
    lean->pitch_per_acceleration = line_to_c(f.pitch_per_acceleration);
  });
}

PLANARVO_API planarvo_status planarvo_evaluate_motions(const planarvo_se2* estimated, const planarvo_se2* truth,
                                                       const double* dt, const int32_t* valid, size_t count,
                                                       double gross_threshold, planarvo_motion_accuracy* accuracy) {
  return guard([&] {
    require(accuracy != nullptr, "planarvo_evaluate_motions: accuracy is NULL");
    planarvo::capi::require_struct_size(accuracy->struct_size,
                                        offsetof(planarvo_motion_accuracy, endpoint_heading) + sizeof(double),
                                        "planarvo_motion_accuracy");
    require(count == 0 || (estimated && truth && dt), "planarvo_evaluate_motions: NULL arrays");
    std::vector<planarvo::SE2> e(count), t(count);
    std::vector<double> d(dt, dt + count);
    std::vector<bool> v;
    for (size_t i = 0; i < count; ++i) {
      e[i] = planarvo::capi::to_cpp(estimated[i]);
      t[i] = planarvo::capi::to_cpp(truth[i]);
      if (valid) v.push_back(valid[i] != 0);
    }
    const auto a = planarvo::track::evaluate_motions(e, t, d, gross_threshold, v);
    planarvo_motion_accuracy out;
    std::memset(&out, 0, sizeof out);
    out.struct_size = accuracy->struct_size;
    out.intervals = a.intervals;
    out.distance = a.distance;
    out.slope_linear = a.slope_linear;
    out.slope_angular = a.slope_angular;
    out.rms_translation = a.rms_translation;
    out.max_translation = a.max_translation;
    out.rms_rotation = a.rms_rotation;
    out.gross_errors = a.gross_errors;
    out.endpoint_error = a.endpoint_error;
    out.endpoint_drift = a.endpoint_drift;
    out.endpoint_heading = a.endpoint_heading;
    std::memcpy(accuracy, &out, std::min(accuracy->struct_size, sizeof out));
  });
}

}  // extern "C"
