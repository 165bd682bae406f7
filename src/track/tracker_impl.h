// Tracker::Impl, private to the tracker's files (tracker.cpp: construction, reset and the public
// calls; tracker_frame.cpp: a frame's steps, its time, loss, grading, the motion and the keyframe
// decision, the shutter and the mounting; tracker_alignment.cpp: the alignment with the keyframe,
// its retries and checks; tracker_keyframes.cpp: keyframes and their pixels; tracker_light.cpp: the
// light fixed to the camera, its learning and refits). Not installed, not included elsewhere.
#pragma once

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
#include "track/tracker.h"
#include "track/tracker_validation.h"
#include "track/warp_model.h"

namespace planarvo::track {

using Status = FrameResult::Status;

inline constexpr int kMinLevelSide = 8;

// The estimate: live pose in the keyframe's robot frame and brightness relative to it.
struct Estimate {
  SE2 T;
  double a = 0.0, b = 0.0;
  BodyAttitude att_ref, att_live;  // the local plane's: the keyframe's and this frame's attitude
  double huber_k = 0.0;  // of the alignment that made it: the finest level's threshold, and that level
  int finest = 0;
};

inline Eigen::Matrix3d lost_covariance() { return Eigen::Matrix3d::Identity(); }

// Reasons, compared by address: each an inline array, one object whichever of the tracker's files
// uses it (a pointer constant to a literal would be one literal per file, and sanitizers do not
// merge them).
inline constexpr char kNoTexture[] = "no texture";
inline constexpr char kMismatch[] = "images do not match";
inline constexpr char kAfterLost[] = "the frame before was lost: the motion is from its predicted pose";
inline constexpr char kMisaligned[] = "misaligned: the images match only where something fixed to the camera is";
inline constexpr char kBrightness[] = "brightness changed too much";
inline constexpr char kWrongSize[] = "frame size differs from the camera's";
inline constexpr char kTimeGap[] = "time gap";
inline constexpr char kWeak[] = "motion poorly constrained";
inline constexpr char kBadTime[] = "timestamp not increasing";
inline constexpr char kNotAligned[] = "not aligned";
inline constexpr char kShutterUnknown[] =
    "rolling shutter at speed with no twist measured before: the keyframe's shear is taken as the mean velocity's";

// The motions against a keyframe whose rolling-shutter twist was not measured (the first frame,
// one after a Lost frame) are Degraded, until a keyframe with a measured twist, when the
// velocity's shift over the readout exceeds this many pixels: the keyframe's shear is taken as the
// first interval's mean, and a robot that accelerates by 1.5 m/s^2 puts about 4 % of that shift
// into the motions (0.4 px here, 0.2 mm on a robot camera at 0.2 m; 1.1 mm and 0.45 mm measured on
// the first two motions at 1.1 m/s with a 25 ms readout).
inline constexpr double kShutterUnknownPx = 10.0;

// Mean squared gradient (grey levels^2 per pixel^2) a frame needs at the coarsest level to
// become a keyframe. A flat or black frame has 0, the pixel noise of a flat frame at level 3
// about 0.01 (1 grey level; 0.09 at 3 grey levels); the shared ground textures seen from the
// paper's configurations have 1.4 (anti_skid_tiles) to 400, but seen far and obliquely by a rear
// camera (1.1 m, 55 degrees from vertical, 60 degree field of view) anti_skid_tiles keeps only
// 0.17 at level 3 (its grout lines are finer than 8 pixels) while it tracks at every frame.
inline constexpr double kMinSelfTexture = 0.1;

// Frames between starting a refit of the photometric model in the background and taking it into
// use: the fit runs beside several frames' tracking instead of in one frame, where it was the p99
// and the largest frame (issue 28). A young model's fit (before kPhotometricSettledFrames: 5 ms
// of host work at 640x480) is taken at the next frame (Impl::start_young_refit); a settled one's
// (up to 20 ms with a lamp, the settled level's two plane fits) at the first keyframe ten frames
// later.
inline constexpr long kYoungRefitLagFrames = 1;
inline constexpr long kSettledRefitLagFrames = 10;


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

  static MountingWatchOptions watch_options(const TrackerOptions& o, const Extrinsics& e);

  // The model in use when it is not the identity: the known one, or a learnt one.
  const PhotometricFit* photometric_model() const;

  void reset();

  // Coarse-to-fine alignment with the keyframe from `init` (the aligner, one pair). Returns false
  // with *reason when the frame cannot be tracked; fills result's per-level fields.
  // refine: from an estimate already close (the same frame aligned a moment ago), the levels from
  // half resolution down only (the match is judged at half resolution).
  bool align(const Pyramid& live, const Estimate& init, Estimate* out, FrameResult* res,
             const char** reason, bool refine = false);

  // The position covariance too large, or much longer along one axis than the other (texture
  // that constrains the motion in one direction only), or the heading too uncertain.
  bool weakly_constrained(const Eigen::Matrix3d& cov) const;

  // FrameResult::texture_residual of an alignment of `live` with the keyframe: one pass of the
  // residual image's kernel at texture_residual_level (NaN when not measured).
  double measure_texture_residual(const Pyramid& live, const Estimate& e);

  // An alignment of `live` with the keyframe, as residual_image.h takes it.
  AlignmentRecord record(const Pyramid& live, const Estimate& e) const;

  // Fills the alignment's covariance, cost, inliers, overlap and the status from the finest
  // level's sums, and the honest-status check (measure_texture_residual) from `live`.
  void finish(FrameResult* res, const Estimate& e, const Pyramid& live);

  // The live frame becomes the keyframe: a pyramid of ours (`slots`) by swapping, one of the
  // caller's by copying on the device.
  void make_keyframe(const Pyramid& live);

  // The frame has texture of its own (at the coarsest level the alignment uses): it can be a
  // keyframe.
  bool has_own_texture(const Pyramid& live);

  // How far apart two twists put the image of the row whose time is furthest from the stamp (the
  // last row's read, or the exposure's middle): the rolling shutter's tolerance measure
  // (level-0 pixels).
  double shutter_shift(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

  // The rolling shutter's part of the live frame's alignment (readout_twist.h): the frame's
  // twist from its alignment; when that moves the image by more than the tolerance from the twist
  // the frame was undistorted with (or the keyframe's twist was not measured), the frame (and the
  // keyframe) undistorted again with it and aligned once more, twice at most. Returns the mean
  // offset the remaining twist error puts in the pose, to be taken out of est (after remember()).
  SE2 take_out_shutter(const Pyramid& live, double t, double dt, FrameResult* res, Estimate* est);

  // The keyframe's subsampled pixels per level (AlignmentLevels::select_block).
  void select_keyframe_pixels();

  void forget_alignment(const char* why);

  void remember(const Pyramid& live, const Estimate& est);

  ResidualImage residuals(int level);

  // The photometric model learns from frames in which the floor moved (light_learning.h), from
  // the first frame, and from a frame it already learnt from at once (correct_again).
  void learn_photometric(const FrameResult& r);

  // The frame aligned once more from `from` after an attempt that gave `before`: on success
  // *again is judged (finish) and counts both attempts' passes and times.
  bool align_again(const Pyramid& live, const Estimate& from, const FrameResult& before, FrameResult* again,
                   Estimate* est, bool refine = false);

  // A frame misaligned with its keyframe by the light fixed to the camera: the model learns from
  // it at once and, when a model can be made, the keyframe and the frame are corrected with it
  // so that the frame can be aligned again. False when nothing changed.
  bool correct_again(const Pyramid& live);

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
  void start_young_refit();

  void take_young_refit();

  void start_refit(bool needed);

  // The refit in the background taken into use when its lag is over: true when the model changed.
  bool refit_taken();

  // The kept keyframe and the live frame corrected again with the model just fitted, so that
  // they are corrected alike (the live frame's alignment starts afresh from them).
  void correct_with_new_model();

  // The motion searched for on the coarsest level around the previous frame's pose
  // (motion_search.h) and the frame aligned from the search's peaks, best first: true with the
  // first result that is not Lost.
  bool search_again(const Pyramid& live, const FrameResult& before, FrameResult* found, Estimate* est);

  FrameResult track_gray(const uint8_t* gray, int width, int height, size_t stride, double t);

  // A tracked frame's attitude to the mounting watch; a change it confirms is reported, and when
  // recalibrating the mounting is turned by it and the attitudes carried on are re-expressed.
  void watch_mounting(double t, double dt, FrameResult* res, Estimate* est);

  bool right_size(const Pyramid& live) const;

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
  FrameTiming advance_time(double t);

  static FrameResult finished(FrameResult& r, const FrameTiming& ft);

  // A Lost frame. can_be_keyframe: it could replace the keyframe (its own texture allows). It does
  // only when the frame before it failed too, the prediction has lapsed (a gap), or the light
  // fixed to the camera held it: a single bad frame (a patch, a dropped half, a flash) must not
  // become the reference of the good frames after it. Until then the next frame is aligned with
  // the old keyframe.
  FrameResult lose(FrameResult& res, const Pyramid& live, const char* why, bool can_be_keyframe, const FrameTiming& ft);

  // The first frame with texture of its own becomes the keyframe.
  FrameResult start(FrameResult& res, const Pyramid& live, const FrameTiming& ft);

  // Align with the keyframe from the prediction; if that fails on the residual, once more from
  // the previous frame's pose (the prediction may be what failed, e.g. after a gap); still lost, a
  // search for the motion around the previous frame's pose (no prior may hold); held by the light
  // fixed to the camera, once more with the photometric model made now.
  bool align_with_retries(const Pyramid& live, const FrameTiming& ft, FrameResult* res, Estimate* est,
                          const char** reason);

  // An Ok frame is Degraded when its time was bad or a gap, its shutter unknown, or the frame
  // before it was lost (its pose is right, but the motion from that frame carries that frame's
  // prediction error; the two motions together are right).
  void grade(FrameResult* res, const char* time_problem);

  // The frame-to-frame motion from the keyframe-relative estimates, its covariance and tilt
  // Jacobian, the pose and velocity; a new keyframe when the overlap or the scale asks.
  void commit(FrameResult* res, Estimate& est, const Pyramid& live, double t, double dt);

  FrameResult track(const Pyramid& live, double t);
};

}  // namespace planarvo::track
