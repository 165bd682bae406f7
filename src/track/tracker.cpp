#include "track/tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "core/error.h"
#include "core/extrinsics.h"
#include "image/pipeline.h"
#include "ocl/runtime.h"
#include "track/alignment_covariance.h"
#include "track/readout_twist.h"
#include "track/tilt_jacobian.h"
#include "track/light_learning.h"
#include "track/texture_residual.h"
#include "track/tracker_validation.h"
#include "track/warp_model.h"

namespace planarvo::track {

namespace {

using Status = FrameResult::Status;

constexpr int kMinLevelSide = 8;

// The estimate: live pose in the keyframe's robot frame and brightness relative to it.
struct Estimate {
  SE2 T;
  double a = 0.0, b = 0.0;
  BodyAttitude att_ref, att_live;  // the local plane's: the keyframe's and this frame's attitude
  double huber_k = 0.0;  // of the alignment that made it: the finest level's threshold, and that level
  int finest = 0;
};

Eigen::Matrix3d lost_covariance() { return Eigen::Matrix3d::Identity(); }

// Reasons (compared by address).
constexpr const char* kNoTexture = "no texture";
constexpr const char* kMismatch = "images do not match";
constexpr const char* kAfterLost = "the frame before was lost: the motion is from its predicted pose";
constexpr const char* kMisaligned = "misaligned: the images match only where something fixed to the camera is";
constexpr const char* kBrightness = "brightness changed too much";
constexpr const char* kWrongSize = "frame size differs from the camera's";
constexpr const char* kTimeGap = "time gap";
constexpr const char* kWeak = "motion poorly constrained";
constexpr const char* kBadTime = "timestamp not increasing";
constexpr const char* kNotAligned = "not aligned";
constexpr const char* kShutterUnknown =
    "rolling shutter at speed with no twist measured before: the keyframe's shear is taken as the mean velocity's";

// The motions against a keyframe whose rolling-shutter twist was not measured (the first frame,
// one after a Lost frame) are Degraded, until a keyframe with a measured twist, when the
// velocity's shift over the readout exceeds this many pixels: the keyframe's shear is taken as the
// first interval's mean, and a robot that accelerates by 1.5 m/s^2 puts about 4 % of that shift
// into the motions (0.4 px here, 0.2 mm on a robot camera at 0.2 m; 1.1 mm and 0.45 mm measured on
// the first two motions at 1.1 m/s with a 25 ms readout).
constexpr double kShutterUnknownPx = 10.0;

// Mean squared gradient (grey levels^2 per pixel^2) a frame needs at the coarsest level to
// become a keyframe. A flat or black frame has 0, the pixel noise of a flat frame at level 3
// about 0.01 (1 grey level; 0.09 at 3 grey levels); the shared ground textures seen from the
// paper's configurations have 1.4 (anti_skid_tiles) to 400, but seen far and obliquely by a rear
// camera (1.1 m, 55 degrees from vertical, 60 degree field of view) anti_skid_tiles keeps only
// 0.17 at level 3 (its grout lines are finer than 8 pixels) while it tracks at every frame.
constexpr double kMinSelfTexture = 0.1;

// Frames between starting a refit of the photometric model in the background and taking it into
// use: the fit runs beside several frames' tracking instead of in one frame, where it was the p99
// and the largest frame (issue 28). A young model's fit (before kPhotometricSettledFrames: 5 ms
// of host work at 640x480) is taken at the next frame (Impl::start_young_refit); a settled one's
// (up to 20 ms with a lamp, the settled level's two plane fits) at the first keyframe ten frames
// later.
constexpr long kYoungRefitLagFrames = 1;
constexpr long kSettledRefitLagFrames = 10;

}  // namespace

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

struct Tracker::Impl {
  ocl::Runtime& rt;
  CameraModel camera;
  Extrinsics ext;
  TrackerOptions opt;
  Aligner aligner;

  Pyramid keyframe;
  bool has_keyframe = false;
  // The keyframe's selected pixels per level (AlignmentLevels::select_block).
  PixelSelector selector;
  std::array<SelectedPixels, kMaxLevels> selection;
  // The camera-frame path: the pipeline and two pyramids, one the keyframe's (aliased by
  // `keyframe`), the other filled with each live frame.
  std::unique_ptr<ImagePipeline> pipeline;
  // The model from TrackerOptions::flat_field, read when the tracker is made (none: learnt).
  std::optional<PhotometricFit> known_photometric;
  Pyramid slots[2];
  int live_slot = 0;
  bool keyframe_is_slot = false;
  SE2 pose;             // accumulated robot pose
  LightLearningGate light_gate;  // when the photometric model learns from a frame
  bool light_holds = false;  // this frame was misaligned (held by the light fixed to the camera?)
  bool keyframe_kept = false;  // the keyframe's camera frame is kept in the pipeline
  bool learnt_this_frame = false;
  // Camera frames handed to the tracker, and the first at which the refit in the background
  // (PhotometricModel::start_refit) may be taken into use (a young model's at that frame, a
  // settled one's at the next keyframe): by the frame count, not by when the worker thread ends,
  // so that tracking is the same however busy the machine is.
  long camera_frames = 0, refit_take_at = 0;
  bool refit_young = false;  // the pending refit is a young model's (kYoungRefitLagFrames)
  // The rolling shutter: the twist the live frame in the pipeline was undistorted with, and
  // whether the keyframe's was measured (not predicted).
  Eigen::Vector3d live_twist = Eigen::Vector3d::Zero();
  bool keyframe_twist_measured = false;
  bool shutter_unknown = false;  // this frame's motion took the keyframe's twist as its own (kShutterUnknownPx)
  // ... and the keyframe's shear is still that assumption (the first keyframe re-undistorted with
  // it, or that frame itself become the keyframe): the motions of the frames aligned with it share
  // its error (0.35-0.45 mm measured on the second), until a keyframe with a measured twist.
  bool keyframe_shear_assumed = false;
  // Frames Lost in a row against the keyframe (keyframe hygiene: one failed frame never becomes
  // the keyframe; the second in a row does, as the keyframe is then what no longer matches).
  int lost_in_a_row = 0;
  bool prev_predicted = false;  // prev.T is a Lost frame's predicted pose, not an alignment
  Estimate prev;        // the previous frame relative to the keyframe
  // Covariance of prev.T less the part the next frame shares with it ((1 - 2 rho) C; zero when
  // the previous frame is the keyframe, lost_covariance() after a Lost frame).
  Eigen::Matrix3d prev_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // se(2) per second
  // The rolling shutter: the twist over the readout (readout_twist.h), the live frame's c (and its
  // time) and the mean offset its remaining twist error puts in its pose.
  ReadoutTwist readout_twist{0.0};
  Eigen::Vector3d live_c = Eigen::Vector3d::Zero();
  double live_tc = 0.0;
  bool has_live_c = false;
  Eigen::Vector3d live_offset = Eigen::Vector3d::Zero();
  double last_t = 0.0, nominal_dt = 0.0, since_good = 0.0;
  bool has_t = false;
  std::array<double, kMaxLevels> sigma{};  // the robust scale per level, from frame to frame
  std::vector<AlignmentPair> pairs = std::vector<AlignmentPair>(1);
  LocalPlane plane;  // TrackerOptions::local_plane: the keyframe's attitude and its covariance
  MountingWatch watch;  // TrackerOptions::on_mounting_change (with the local plane)
  // Tracker::set_odometry: the wheels' pose at the frame about to be tracked and at the last one,
  // and the distance between them (NaN without both).
  std::optional<SE2> next_odometry, last_odometry;
  double odometry_distance = NAN;
  AlignmentReport report;
  // The last frame's final alignment for residuals() (has_last), or why there is none (missing;
  // nullptr: no frame aligned since the first), and the residual image made from it (cached,
  // level -1: none yet). The copy path's spare keyframe pyramid keeps the keyframe a frame that
  // became the keyframe was aligned with.
  AlignmentRecord last;
  bool has_last = false;
  const char* missing = nullptr;
  std::unique_ptr<ResidualImager> imager;
  std::unique_ptr<MotionSearch> search;  // made when first needed
  // TrackerOptions::tilt_jacobian: made when first needed, and d prev.T / d (roll, pitch).
  std::unique_ptr<TiltJacobian> tilt_jacobian;
  Eigen::Matrix<double, 3, 2> prev_tilt = Eigen::Matrix<double, 3, 2>::Zero();
  ResidualImage cached;
  Pyramid spare;

  Impl(ocl::Runtime& r, const CameraModel& c, const Extrinsics& e, const TrackerOptions& o)
      : rt(r), camera(validated_tracker_camera(c, e, o)), ext(e), opt(o),
        aligner(r, c.K(), o, o.local_plane ? AlignerModel::LocalPlane : AlignerModel::Motion), selector(r),
        light_gate(camera.K(), camera.width, camera.height, e, o.learn_motion_px, o.max_texture_residual),
        plane(o.local_plane_prior_sigma), watch(watch_options(o, e)) {
    readout_twist = ReadoutTwist(camera.mean_row_time());
    // The honest-status check runs on every aligned frame: its programs are built now, not at the
    // first aligned frame (whose latency a cold kernel cache would otherwise carry).
    if (std::isfinite(opt.max_texture_residual)) imager = std::make_unique<ResidualImager>(rt, camera.K(), opt.kernel);
    // The flat field is read now, so that a bad file fails at once rather than at the first frame.
    if (!opt.flat_field.empty() && opt.photometric.enabled) {
      const UndistortMap map = compute_undistort_map(camera);
      const cv::Mat valid = cv::Mat(map.height, map.width, CV_8UC1, const_cast<uint8_t*>(map.valid.data())).clone();
      known_photometric = flat_field_photometric(
          flat_field_to_undistorted(read_flat_field(opt.flat_field, camera.width, camera.height), map), valid,
          opt.photometric);
    }
    reset();
  }

  static MountingWatchOptions watch_options(const TrackerOptions& o, const Extrinsics& e) {
    MountingWatchOptions w = o.mounting_watch;
    w.height = e.z;
    return w;
  }

  // The model in use when it is not the identity: the known one, or a learnt one.
  const PhotometricFit* photometric_model() const {
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

  void reset() {
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

  // Coarse-to-fine alignment with the keyframe from `init` (the aligner, one pair). Returns false
  // with *reason when the frame cannot be tracked; fills result's per-level fields.
  // refine: from an estimate already close (the same frame aligned a moment ago), the levels from
  // half resolution down only (the match is judged at half resolution).
  bool align(const Pyramid& live, const Estimate& init, Estimate* out, FrameResult* res,
             const char** reason, bool refine = false) {
    AlignmentPair& pair = pairs[0];
    pair.reference = &keyframe;
    pair.live = &live;
    pair.selection = &selection;
    pair.motion = init.T;
    pair.log_gain = init.a;
    pair.bias = init.b;
    pair.sigma = sigma;
    if (opt.local_plane) plane.prepare(init.att_live, &pair);
    Extrinsics e = ext;
    AlignmentLevels levels = aligner.levels(keyframe, live);
    if (refine) levels.coarsest = std::max(levels.finest, std::min(1, levels.coarsest));
    report = aligner.align(pairs, &e, levels);
    res->iterations = report.passes;
    res->level_ms = report.level_ms;
    res->levels_used = report.levels_used;
    // A frame about to become the keyframe goes on to full resolution.
    const ReduceSums* s = report.ok ? &report.finest[0] : nullptr;
    if (s && levels.finest > 0 && opt.refine_keyframes && s->ref > 0 && s->valid / s->ref < opt.keyframe_overlap) {
      levels.coarsest = levels.finest = 0;
      const std::array<int, kMaxLevels> passes = report.passes;
      const std::array<double, kMaxLevels> ms = report.level_ms;
      report = aligner.align(pairs, &e, levels);
      for (size_t l = 0; l < passes.size(); ++l) {
        res->iterations[l] = passes[l] + report.passes[l];
        res->level_ms[l] = ms[l] + report.level_ms[l];
      }
      res->levels_used += report.levels_used;
    }
    sigma = pair.sigma;
    if (!report.ok) {
      *reason = report.reason;
      return false;
    }
    out->T = pair.motion;
    out->a = pair.log_gain;
    out->b = pair.bias;
    out->att_ref = pair.reference_attitude;
    out->att_live = pair.live_attitude;
    out->huber_k = report.finest_huber_k.empty() ? 0.0 : report.finest_huber_k[0];
    out->finest = levels.finest;
    return true;
  }

  // The position covariance too large, or much longer along one axis than the other (texture
  // that constrains the motion in one direction only), or the heading too uncertain.
  bool weakly_constrained(const Eigen::Matrix3d& cov) const {
    const Eigen::Vector2d ev =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov.topLeftCorner<2, 2>()).eigenvalues();
    return !(std::sqrt(ev(1)) <= opt.max_position_std) || !(ev(1) <= opt.max_std_ratio * opt.max_std_ratio * ev(0)) ||
           !(std::sqrt(cov(2, 2)) <= opt.max_heading_std);
  }

  // FrameResult::texture_residual of an alignment of `live` with the keyframe: one pass of the
  // residual image's kernel at texture_residual_level (NaN when not measured).
  double measure_texture_residual(const Pyramid& live, const Estimate& e) {
    const int level = texture_residual_level(camera.width, opt.levels);
    if (!std::isfinite(opt.max_texture_residual) || level >= live.num_levels() || level >= keyframe.num_levels())
      return std::numeric_limits<double>::quiet_NaN();
    return imager->texture_residual(record(live, e), ext, level);  // made with the tracker
  }

  // An alignment of `live` with the keyframe, as residual_image.h takes it.
  AlignmentRecord record(const Pyramid& live, const Estimate& e) const {
    AlignmentRecord a;
    a.reference = keyframe;
    a.live = live;
    a.motion = e.T;
    a.log_gain = e.a;
    a.bias = e.b;
    a.huber_k = e.huber_k;
    a.finest_level = e.finest;
    a.reference_attitude = e.att_ref;
    a.live_attitude = e.att_live;
    return a;
  }

  // Fills the alignment's covariance, cost, inliers, overlap and the status from the finest
  // level's sums, and the honest-status check (measure_texture_residual) from `live`.
  void finish(FrameResult* res, const Estimate& e, const Pyramid& live) {
    const ReduceSums& s = report.finest[0];
    res->final_cost = s.valid > 0 ? s.cost / s.valid : HUGE_VAL;
    res->inlier_fraction = s.valid > 0 ? s.inlier / s.valid : 0.0;
    res->overlap = s.ref > 0 ? s.valid / s.ref : 0.0;
    res->log_gain = e.a;
    res->bias = e.b;
    const int nb = opt.estimate_brightness ? 2 : 0;
    const int n = report.finest_nparam + nb;  // motion (the local plane's attitudes), brightness
    const double dof = std::max(1.0, s.valid - n);
    res->sigma = report.finest_sigma[0];
    // The independent-pixel covariance sigma^2 (J^T W J)^-1 (sigma^2 at least min_sigma^2, so
    // noise-free synthetic frames do not claim zero variance) judges how well the texture
    // constrains the motion (the thresholds below were measured with it).
    const double floor_s2 = opt.min_sigma * opt.min_sigma;
    const double s2 = std::max(s.wrr / dof, floor_s2);
    const MatrixJ A = s.JtWJ.topLeftCorner(n, n);
    const Eigen::LDLT<MatrixJ> ldlt(A);
    const MatrixJ inv = ldlt.solve(MatrixJ::Identity(n, n));
    Eigen::Matrix3d independent = s2 * inv.topLeftCorner(3, 3);
    if (!independent.allFinite()) independent = lost_covariance();
    // The motion's covariance is composed from this one by the caller (track_gray).
    const MatrixJ C =
        alignment_covariance_all(s, report.finest_stats[0], n, floor_s2, A, ldlt, opt.covariance_step_fraction);
    res->alignment_covariance = C.topLeftCorner(3, 3);
    if (!res->alignment_covariance.allFinite()) res->alignment_covariance = lost_covariance();
    if (opt.local_plane) {
      // The live attitude (parameters 5, 6: after the motion and the keyframe's attitude), from
      // the last level that estimated the attitudes: the finest (C above) unless attitude_max_width
      // held them on the finer levels.
      res->attitude = e.att_live;
      res->attitude_covariance = plane.prior_covariance();
      const int lv = kMotionParams + 2;
      Eigen::Matrix2d cov = Eigen::Matrix2d::Constant(NAN);
      if (report.finest_nparam == kMotionParams + kAttitudeParams) {
        cov = C.block(lv, lv, 2, 2);
      } else if (report.attitude_level >= 0) {
        const int na = kMotionParams + kAttitudeParams + nb;
        const ReduceSums& sa = report.attitude_sums;
        const MatrixJ Aa = sa.JtWJ.topLeftCorner(na, na);
        const Eigen::LDLT<MatrixJ> la(Aa);
        cov = alignment_covariance_all(sa, report.attitude_stats, na, floor_s2, Aa, la, opt.covariance_step_fraction)
                  .block(lv, lv, 2, 2);
      }
      if (cov.allFinite()) res->attitude_covariance = cov;
      // Observed when the images know it better than the prior alone does.
      res->attitude_observed = res->attitude_covariance.diagonal().maxCoeff() < 0.5 * plane.prior_covariance()(0, 0);
    }

    // The images' match from the half-resolution level (or the finest, when coarser): at full
    // resolution a noisy, weakly textured view's residual is mostly pixel noise.
    const ReduceSums& st = report.match_stats[0];
    const double var_ref = st.valid > 0 ? st.iref2 / st.valid - std::pow(st.iref / st.valid, 2) : 0.0;
    const double ratio = st.valid > 0 && var_ref > 0 ? (st.rr / st.valid) / var_ref : HUGE_VAL;
    // The floor's texture left in the residual: an alignment that something fixed to the camera
    // holds while the floor moves leaves it there. Images that do not match at all (a frame with
    // nothing in common with the keyframe, as after a gap at speed) say nothing about the light,
    // and forced a model learnt from a few frames into use.
    res->texture_residual = measure_texture_residual(live, e);
    const bool misaligned = res->texture_residual > opt.max_texture_residual;
    light_holds = misaligned && ratio <= opt.lost_residual_ratio;
    if (!(ratio <= opt.lost_residual_ratio)) {
      res->status = Status::Lost;
      res->reason = kMismatch;
    } else if (misaligned) {
      res->status = Status::Lost;
      res->reason = kMisaligned;
    } else if (!(std::abs(e.a) <= opt.max_log_gain)) {
      res->status = Status::Lost;
      res->reason = kBrightness;
    } else if (ratio > opt.degraded_residual_ratio) {
      res->status = Status::Degraded;
      res->reason = "large residuals";
    } else if (res->inlier_fraction < opt.min_inlier_fraction) {
      res->status = Status::Degraded;
      res->reason = "few inliers";
    } else if (weakly_constrained(independent)) {
      res->status = Status::Degraded;
      res->reason = kWeak;
    } else {
      res->status = Status::Ok;
      res->reason = "";
    }
  }

  // The live frame becomes the keyframe: a pyramid of ours (`slots`) by swapping, one of the
  // caller's by copying on the device.
  void make_keyframe(const Pyramid& live) {
    if (&live == &slots[live_slot]) {
      keyframe = live;
      keyframe_is_slot = true;
      live_slot ^= 1;
      // A new photometric model is taken into use with a new keyframe: the frame (still in the
      // pipeline) is corrected again with it. Its fit was started at an earlier keyframe
      // (kSettledRefitLagFrames).
      PhotometricModel* photometric = pipeline ? pipeline->photometric() : nullptr;
      if (photometric && refit_taken()) pipeline->reprocess(keyframe);
      if (photometric && photometric->refit_due(light_holds)) start_refit(light_holds);
      // Its frame stays on the device, so that a model made at a later frame can correct the
      // keyframe again (correct_again), or a measured twist undistort it again (take_out_shutter).
      if (photometric || camera.timed_rows()) {
        pipeline->keep();
        keyframe_kept = true;
      }
    } else {
      // Copied into the spare pyramid, which then swaps with the keyframe's: the old keyframe's
      // contents stay for residuals() until the next frame (no more copying than in place).
      if (spare.levels.size() != live.levels.size()) spare.levels.clear();
      for (size_t l = 0; l < live.levels.size(); ++l) {
        const PyramidLevel& src = live.levels[l];
        if (spare.levels.size() <= l) spare.levels.push_back(PyramidLevel());
        PyramidLevel& dst = spare.levels[l];
        const size_t bytes = static_cast<size_t>(src.width) * src.height * 16;
        if (dst.width != src.width || dst.height != src.height || !dst.data()) {
          dst.width = src.width;
          dst.height = src.height;
          dst.data = cl::Buffer(rt.context(), CL_MEM_READ_WRITE, bytes);
        }
        rt.queue().enqueueCopyBuffer(src.data, dst.data, 0, 0, bytes);
      }
      std::swap(keyframe, spare);
      keyframe_kept = false;
      if (keyframe_is_slot) spare = Pyramid();  // a slot's buffers are the pipeline's, not spare
      keyframe_is_slot = false;
    }
    select_keyframe_pixels();
    has_keyframe = true;
    prev = Estimate();
    prev.att_ref = prev.att_live = plane.keyframe();
    prev_predicted = false;
    prev_covariance.setZero();
    prev_tilt.setZero();
    // A frame whose own twist was taken as the interval's mean velocity passes that on.
    keyframe_shear_assumed = shutter_unknown;
  }

  // The frame has texture of its own (at the coarsest level the alignment uses): it can be a
  // keyframe.
  bool has_own_texture(const Pyramid& live) {
    int coarse = std::min(opt.levels, live.num_levels()) - 1;
    while (coarse > 0 && (live.levels[static_cast<size_t>(coarse)].width < kMinLevelSide ||
                          live.levels[static_cast<size_t>(coarse)].height < kMinLevelSide))
      --coarse;
    return aligner.texture(live, coarse) >= kMinSelfTexture;
  }

  // How far apart two twists put the image of the row whose time is furthest from the stamp (the
  // last row's read, or the exposure's middle): the rolling shutter's tolerance measure
  // (level-0 pixels).
  double shutter_shift(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    const double top = camera.row_time(0.0), bottom = camera.row_time(camera.height - 1.0);
    const double r = std::abs(bottom) >= std::abs(top) ? bottom : top;
    return max_pixel_displacement(camera.K(), ext, SE2::exp(a * r), SE2::exp(b * r), camera.width, camera.height);
  }

  // The rolling shutter's part of the live frame's alignment (readout_twist.h): the frame's
  // twist from its alignment; when that moves the image by more than the tolerance from the twist
  // the frame was undistorted with (or the keyframe's twist was not measured), the frame (and the
  // keyframe) undistorted again with it and aligned once more, twice at most. Returns the mean
  // offset the remaining twist error puts in the pose, to be taken out of est (after remember()).
  SE2 take_out_shutter(const Pyramid& live, double t, double dt, FrameResult* res, Estimate* est) {
    live_offset.setZero();
    if (!camera.timed_rows() || !(dt > 0.0) || &live != &slots[live_slot] || !keyframe_kept) return SE2();
    for (int round = 0;; ++round) {
      const Eigen::Vector3d v = (prev.T.inverse() * est->T).log() / dt;
      const bool keyframe_too = !keyframe_twist_measured;
      Eigen::Vector3d twist;
      if (keyframe_too) {
        // The keyframe was undistorted with the same twist as this frame (none measured yet), so
        // their relative pose does not depend on it, and the velocity is the twist's measure.
        // (readout_twist.measure's model holds once the keyframe's own twist is right: with it
        // here, a robot that starts, or recovers, at speed undistorts the keyframe with 1/(1+k)
        // of its twist and the frames stop matching.)
        live_c = v;
        live_tc = t - 0.5 * dt;
        twist = v;
        shutter_unknown = keyframe_shear_assumed = shutter_shift(Eigen::Vector3d::Zero(), v) > kShutterUnknownPx;
      } else {
        twist = readout_twist.measure(t, dt, v, live_twist, &live_c, &live_tc);
      }
      has_live_c = twist.allFinite();
      if (!has_live_c) return SE2();
      if (round == 2 || (!keyframe_too && shutter_shift(live_twist, twist) <= opt.rolling_shutter_tolerance_px)) {
        live_offset = camera.mean_row_time() * (live_twist - twist);
        return SE2::exp(live_offset);
      }
      if (keyframe_too) {
        // The keyframe was the previous frame (the first, or one after a Lost frame): this
        // frame's twist is the best measure of its own.
        pipeline->set_kept_row_warp(rolling_shutter_warp(camera, ext, twist));
        pipeline->reprocess_kept(keyframe);
        select_keyframe_pixels();
        keyframe_twist_measured = true;
      }
      live_twist = twist;
      pipeline->set_row_warp(rolling_shutter_warp(camera, ext, twist));
      pipeline->reprocess(slots[live_slot]);
      FrameResult again;
      Estimate e;
      if (!align_again(live, *est, *res, &again, &e, true)) return SE2();
      *res = again;
      *est = e;
    }
  }

  // The keyframe's subsampled pixels per level (AlignmentLevels::select_block).
  void select_keyframe_pixels() {
    const AlignmentLevels levels = aligner.levels(keyframe, keyframe);
    for (int l = 0; l < keyframe.num_levels() && l < kMaxLevels; ++l) {
      const auto L = static_cast<size_t>(l);
      if (levels.select_block[L] >= 2)
        selector.run(keyframe.levels[L], l, levels.select_block[L], &selection[L]);
      else
        selection[L] = SelectedPixels();
    }
  }

  void forget_alignment(const char* why) {
    has_last = false;
    missing = why;
    cached.level = -1;
  }

  void remember(const Pyramid& live, const Estimate& est) {
    last = record(live, est);
    has_last = true;
  }

  ResidualImage residuals(int level) {
    if (!has_last && !missing)
      throw_invalid_argument("Tracker::residuals: no frame has been aligned with a keyframe yet");
    if (!has_last)
      throw Error(ErrorCode::Failed, std::string("Tracker::residuals: the last frame was not aligned (") + missing + ")");
    if (cached.level != level) {
      if (!imager) imager = std::make_unique<ResidualImager>(rt, camera.K(), opt.kernel);
      cached.level = -1;
      imager->compute(last, ext, level, &cached);
    }
    return cached;
  }

  // The photometric model learns from frames in which the floor moved (light_learning.h), from
  // the first frame, and from a frame it already learnt from at once (correct_again).
  void learn_photometric(const FrameResult& r) {
    PhotometricModel* photometric = pipeline->photometric();
    if (!photometric || !photometric->learning()) return;
    if (learnt_this_frame || r.status == Status::First) {
      if (!learnt_this_frame) pipeline->learn();
      learnt_this_frame = false;
      light_gate.learnt();
      return;
    }
    if (light_gate.learn_from(r)) pipeline->learn();
  }

  // The frame aligned once more from `from` after an attempt that gave `before`: on success
  // *again is judged (finish) and counts both attempts' passes and times.
  bool align_again(const Pyramid& live, const Estimate& from, const FrameResult& before, FrameResult* again,
                   Estimate* est, bool refine = false) {
    *again = before;
    const char* reason = "";
    if (!align(live, from, est, again, &reason, refine)) return false;
    finish(again, *est, live);
    for (size_t l = 0; l < before.iterations.size(); ++l) {
      again->iterations[l] += before.iterations[l];
      again->level_ms[l] += before.level_ms[l];
    }
    return true;
  }

  // A frame misaligned with its keyframe by the light fixed to the camera: the model learns from
  // it at once and, when a model can be made, the keyframe and the frame are corrected with it
  // so that the frame can be aligned again. False when nothing changed.
  bool correct_again(const Pyramid& live) {
    PhotometricModel* photometric = pipeline ? pipeline->photometric() : nullptr;
    if (!photometric || !photometric->learning() || &live != &slots[live_slot] || !keyframe_kept) return false;
    if (!learnt_this_frame) {
      pipeline->learn();
      learnt_this_frame = true;
    }
    if (!photometric->refit_due(true)) return false;
    photometric->refit(true);
    correct_with_new_model();
    return true;
  }

  // Until the statistics settle (kPhotometricSettledFrames), the model is refitted as soon as a
  // fit is due and taken into use at once, not at the next keyframe (as later ones are): before
  // it the light fixed to the camera pulls at every alignment, and at a slow start the first
  // keyframe lasts a second or more (a shadow's edge and a lamp's falloff held frames 1-3 mm off
  // there). A model already in use (one the light forced from a few frames, correct_again) is
  // rough: it is refitted, as a needed one, whenever a quarter more frames (at least one) were
  // learnt. The keyframe is corrected again with the new model, and the live frame.
  // The fit is started when the frame that made it due has been learnt from (start_young_refit,
  // at the end of a frame) and taken at the next frame, once its pipeline is done (take_young_refit):
  // the model in use is the one a refit at that frame would make, and the fit runs in the time
  // between the two frames (hidden at a camera's frame rate) and beside the next one's pipeline.
  // (Taken three frames later, the lamp, reflection and shadow together held the first second's
  // frames: RMS 0.045 -> 0.155 mm on configuration 1 over asphalt, frames lost.)
  void start_young_refit() {
    PhotometricModel* photometric = pipeline ? pipeline->photometric() : nullptr;
    if (!photometric || !photometric->learning() || !has_keyframe || !keyframe_kept || photometric->refit_pending())
      return;
    const PhotometricFit& fit = photometric->fit();
    if (fit.frames >= kPhotometricSettledFrames) return;
    const bool rough = !fit.identity;
    if (rough ? photometric->frames() - fit.frames < std::max(1, fit.frames / 4) : !photometric->refit_due()) return;
    start_refit(rough);
  }

  void take_young_refit() {
    PhotometricModel* photometric = pipeline ? pipeline->photometric() : nullptr;
    // A settled model's refit is taken at a keyframe (make_keyframe).
    if (!photometric || !photometric->refit_pending() || !refit_young) return;
    const bool was_identity = photometric->fit().identity;
    if (refit_taken() && !(was_identity && photometric->fit().identity) && has_keyframe && keyframe_kept)
      correct_with_new_model();
  }

  void start_refit(bool needed) {
    PhotometricModel* photometric = pipeline->photometric();
    if (photometric->refit_pending()) return;
    photometric->start_refit(needed);
    refit_young = photometric->frames() < kPhotometricSettledFrames;
    refit_take_at = camera_frames + (refit_young ? kYoungRefitLagFrames : kSettledRefitLagFrames);
  }

  // The refit in the background taken into use when its lag is over: true when the model changed.
  bool refit_taken() {
    PhotometricModel* photometric = pipeline->photometric();
    return photometric->refit_pending() && camera_frames >= refit_take_at && photometric->take_refit();
  }

  // The kept keyframe and the live frame corrected again with the model just fitted, so that
  // they are corrected alike (the live frame's alignment starts afresh from them).
  void correct_with_new_model() {
    pipeline->reprocess_kept(keyframe);
    pipeline->reprocess(slots[live_slot]);
    select_keyframe_pixels();
  }

  // The motion searched for on the coarsest level around the previous frame's pose
  // (motion_search.h) and the frame aligned from the search's peaks, best first: true with the
  // first result that is not Lost.
  bool search_again(const Pyramid& live, const FrameResult& before, FrameResult* found, Estimate* est) {
    if (!search) search = std::make_unique<MotionSearch>(rt);
    const AlignmentLevels levels = aligner.levels(keyframe, live);
    const std::vector<SE2> peaks =
        search->candidates(keyframe, live, levels.coarsest, camera.K(), ext, prev.T, opt.search);
    for (const SE2& peak : peaks) {
      Estimate from = prev;
      from.T = peak;
      if (align_again(live, from, before, found, est) && found->status != Status::Lost) return true;
    }
    return false;
  }

  FrameResult track_gray(const uint8_t* gray, int width, int height, size_t stride, double t) {
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

  // A tracked frame's attitude to the mounting watch; a change it confirms is reported, and when
  // recalibrating the mounting is turned by it and the attitudes carried on are re-expressed.
  void watch_mounting(double t, double dt, FrameResult* res, Estimate* est) {
    using Response = TrackerOptions::MountingResponse;
    // A frame whose attitude the images did not observe says nothing about the mounting.
    if (!opt.local_plane || opt.on_mounting_change == Response::Ignore || !res->attitude_observed) return;
    const std::optional<MountingChange> change =
        watch.add(t, dt, res->motion.value, res->attitude, res->attitude_covariance, odometry_distance);
    if (!change) return;
    res->mounting_changed = true;
    res->mounting_change = *change;
    res->changed_mounting = turned_mounting(ext, change->step, change->dyaw);
    res->changed_mounting.z += change->dz;
    if (opt.on_mounting_change != Response::Recalibrate) return;
    ext = res->changed_mounting;
    est->att_ref = relative_to_turned(est->att_ref, change->step, change->dyaw);
    est->att_live = relative_to_turned(est->att_live, change->step, change->dyaw);
    res->attitude = est->att_live;
    plane.mounting_turned(change->step, change->dyaw);
    watch.mounting_changed(*change);
  }

  bool right_size(const Pyramid& live) const {
    if (live.num_levels() < 1) return false;
    for (int l = 0; l < live.num_levels(); ++l) {
      const PyramidLevel& p = live.levels[static_cast<size_t>(l)];
      if (p.width != level_size(camera.width, l) || p.height != level_size(camera.height, l) || !p.data())
        return false;
    }
    return true;
  }

  // track()'s steps. The frame's time: the interval, a gap or a bad stamp, and the
  // constant-velocity prediction.
  struct FrameTiming {
    std::chrono::steady_clock::time_point start;
    double dt = 0.0;
    const char* problem = nullptr;  // kBadTime, kTimeGap or none
    bool predict = false;
    SE2 predicted;
  };

  // A timestamp that is not finite or not after the last one is not used (the usual interval is
  // assumed).
  FrameTiming advance_time(double t) {
    FrameTiming ft;
    if (has_t) {
      ft.dt = std::isfinite(t) ? t - last_t : HUGE_VAL;
      if (!(ft.dt > 0.0) || !std::isfinite(ft.dt)) {
        ft.problem = kBadTime;
        ft.dt = nominal_dt;
      } else if (nominal_dt > 0.0 && ft.dt > opt.max_gap_factor * nominal_dt) {
        ft.problem = kTimeGap;
      } else {
        nominal_dt = nominal_dt > 0.0 ? 0.9 * nominal_dt + 0.1 * ft.dt : ft.dt;
      }
    }
    if (std::isfinite(t) && (!has_t || t > last_t)) {
      last_t = t;
      has_t = true;
    }
    since_good += ft.dt;
    ft.predict = ft.dt > 0.0 && since_good <= opt.max_gap_seconds;
    ft.predicted = ft.predict ? SE2::exp(velocity * ft.dt) : SE2();
    return ft;
  }

  static FrameResult finished(FrameResult& r, const FrameTiming& ft) {
    r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - ft.start).count();
    return r;
  }

  // A Lost frame. can_be_keyframe: it could replace the keyframe (its own texture allows). It does
  // only when the frame before it failed too, the prediction has lapsed (a gap), or the light
  // fixed to the camera held it: a single bad frame (a patch, a dropped half, a flash) must not
  // become the reference of the good frames after it. Until then the next frame is aligned with
  // the old keyframe.
  FrameResult lose(FrameResult& res, const Pyramid& live, const char* why, bool can_be_keyframe, const FrameTiming& ft) {
    res.status = Status::Lost;
    res.reason = why;
    res.motion.value = ft.predicted;
    res.motion.covariance = res.alignment_covariance = lost_covariance();
    if (opt.local_plane) {
      res.attitude = prev.att_live;
      res.attitude_covariance = plane.prior_covariance();
    }
    pose = pose * ft.predicted;
    ++lost_in_a_row;
    // A frame misaligned by the light fixed to the camera is not a bad frame: the keyframe and
    // the light's model are what failed, and a new keyframe takes a new model into use.
    if (can_be_keyframe && (lost_in_a_row >= 2 || !ft.predict || why == kMisaligned)) {
      if (opt.local_plane) plane.take_keyframe(prev.att_live, plane.prior_covariance());
      make_keyframe(live);
      keyframe_twist_measured = false;
      res.keyframe = true;
    } else {
      // The next motion is from this predicted pose: as uncertain as this one.
      prev.T = prev.T * ft.predicted;
      prev_covariance = lost_covariance();
      prev_predicted = true;
    }
    if (since_good > opt.max_gap_seconds) {
      velocity.setZero();
      readout_twist.reset();
    }
    return finished(res, ft);
  }

  // The first frame with texture of its own becomes the keyframe.
  FrameResult start(FrameResult& res, const Pyramid& live, const FrameTiming& ft) {
    missing = nullptr;  // nothing to align with: not a failure of this frame's alignment
    if (!has_own_texture(live)) {
      res.status = Status::Lost;
      res.reason = kNoTexture;
      return finished(res, ft);
    }
    make_keyframe(live);
    keyframe_twist_measured = false;
    lost_in_a_row = 0;
    res.status = Status::First;
    if (opt.local_plane) {
      res.attitude = plane.keyframe();
      res.attitude_covariance = plane.keyframe_covariance();
    }
    res.keyframe = true;
    since_good = 0.0;
    return finished(res, ft);
  }

  // Align with the keyframe from the prediction; if that fails on the residual, once more from
  // the previous frame's pose (the prediction may be what failed, e.g. after a gap); still lost, a
  // search for the motion around the previous frame's pose (no prior may hold); held by the light
  // fixed to the camera, once more with the photometric model made now.
  bool align_with_retries(const Pyramid& live, const FrameTiming& ft, FrameResult* res, Estimate* est,
                          const char** reason) {
    Estimate init = prev;
    init.T = prev.T * ft.predicted;
    bool ok = align(live, init, est, res, reason);
    if (ok) finish(res, *est, live);
    if ((!ok || res->status == Status::Lost) && *reason != kAlignNoLiveTexture &&
        !(ft.predicted.x == 0 && ft.predicted.y == 0 && ft.predicted.theta == 0)) {
      FrameResult retry;
      Estimate est2;
      if (align_again(live, prev, *res, &retry, &est2) && retry.status != Status::Lost) {
        *res = retry;
        *est = est2;
        ok = true;
      }
    }
    if ((!ok || res->status == Status::Lost) && *reason != kAlignNoLiveTexture && opt.search_motion) {
      FrameResult found;
      Estimate est4;
      if (search_again(live, *res, &found, &est4)) {
        *res = found;
        *est = est4;
        ok = true;
      }
    }
    if (ok && res->status == Status::Lost && res->reason == kMisaligned && correct_again(live)) {
      FrameResult again;
      Estimate est3;
      if (align_again(live, init, *res, &again, &est3)) {
        *res = again;
        *est = est3;
      }
    }
    return ok;
  }

  // An Ok frame is Degraded when its time was bad or a gap, its shutter unknown, or the frame
  // before it was lost (its pose is right, but the motion from that frame carries that frame's
  // prediction error; the two motions together are right).
  void grade(FrameResult* res, const char* time_problem) {
    if (time_problem && res->status == Status::Ok) {
      res->status = Status::Degraded;
      res->reason = time_problem;
    }
    if ((shutter_unknown || keyframe_shear_assumed) && res->status == Status::Ok) {
      res->status = Status::Degraded;
      res->reason = kShutterUnknown;
    }
    if (prev_predicted && res->status == Status::Ok) {
      res->status = Status::Degraded;
      res->reason = kAfterLost;
    }
    prev_predicted = false;
  }

  // The frame-to-frame motion from the keyframe-relative estimates, its covariance and tilt
  // Jacobian, the pose and velocity; a new keyframe when the overlap or the scale asks.
  void commit(FrameResult* res, Estimate& est, const Pyramid& live, double t, double dt) {
    // With prev.T = P exp(xi_p) and est.T = E exp(xi_e), the motion is m exp(xi_e - Ad(m^-1) xi_p);
    // prev_covariance already holds xi_p's covariance less the part shared with xi_e.
    res->motion.value = prev.T.inverse() * est.T;
    const Eigen::Matrix3d ad = res->motion.value.inverse().adjoint();
    res->motion.covariance = res->alignment_covariance + ad * prev_covariance * ad.transpose();
    // Its tilt Jacobian the same way: xi_e's and Ad(m^-1) xi_p's (before a new keyframe).
    Eigen::Matrix<double, 3, 2> tilt = Eigen::Matrix<double, 3, 2>::Zero();
    if (opt.tilt_jacobian) {
      if (!tilt_jacobian) tilt_jacobian = std::make_unique<TiltJacobian>(rt, opt.kernel);
      tilt = (*tilt_jacobian)(keyframe, live, camera.K(), ext, est.T, est.a, est.b, est.huber_k, opt.estimate_brightness);
      res->motion_tilt_jacobian = tilt - ad * prev_tilt;
    }
    if (!res->motion.covariance.allFinite()) res->motion.covariance = lost_covariance();
    pose = pose * res->motion.value;
    if (dt > 0.0) velocity = res->motion.value.log() / dt;
    if (has_live_c) readout_twist.commit(live_c, live_tc);
    watch_mounting(t, dt, res, &est);
    since_good = 0.0;
    lost_in_a_row = 0;
    if (res->overlap < opt.keyframe_overlap ||
        log_scale_change(camera.K(), ext, est.T, camera.region()) > opt.keyframe_scale_change) {
      if (opt.local_plane) plane.take_keyframe(est.att_live, res->attitude_covariance);
      make_keyframe(live);
      keyframe_twist_measured = true;
      // Frames aligned with it carry its own shutter offset, which the motions from it must not.
      prev.T = SE2::exp(live_offset);
      res->keyframe = true;
    } else {
      prev = est;
      prev_tilt = tilt;
      prev_covariance = (1.0 - 2.0 * opt.consecutive_alignment_correlation) * res->alignment_covariance;
    }
  }

  FrameResult track(const Pyramid& live, double t) {
    const auto t0 = std::chrono::steady_clock::now();
    has_live_c = false;
    forget_alignment(kNotAligned);
    FrameResult res;
    res.motion.covariance = lost_covariance();
    res.mounting = ext;
    if (next_odometry && last_odometry) {
      const SE2 d = last_odometry->inverse() * *next_odometry;
      odometry_distance = std::hypot(d.x, d.y);
    } else {
      odometry_distance = NAN;
    }
    last_odometry = next_odometry;
    next_odometry.reset();
    shutter_unknown = false;
    FrameTiming ft = advance_time(t);
    ft.start = t0;

    if (!right_size(live)) {
      missing = kWrongSize;
      return lose(res, live, kWrongSize, false, ft);
    }
    if (!has_keyframe) return start(res, live, ft);

    Estimate est;
    const char* reason = "";
    const bool ok = align_with_retries(live, ft, &res, &est, &reason);
    const SE2 shutter_offset = ok && res.status != Status::Lost ? take_out_shutter(live, t, ft.dt, &res, &est) : SE2();
    if (ok) remember(live, est);  // before a new keyframe replaces the one aligned with
    else missing = reason;
    est.T = est.T * shutter_offset;
    // "No texture in the live frame" compares it with the keyframe: a frame with texture of its
    // own may still replace a keyframe whose texture the frames after it no longer show.
    if (!ok) return lose(res, live, reason, reason != kAlignNoLiveTexture || has_own_texture(live), ft);
    if (res.status == Status::Lost) return lose(res, live, res.reason, true, ft);
    grade(&res, ft.problem);
    commit(&res, est, live, t, ft.dt);
    return finished(res, ft);
  }
};

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
