// The dense planar tracker (paper section 4): aligns every live frame's pyramid with a reference
// keyframe by ESM Gauss-Newton steps over the robot's planar motion and an affine brightness
// change, coarse to fine, and reports the frame-to-frame motion in the robot frame. Design
// and measurements: src/track/README.md.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "core/body_attitude.h"
#include "core/extrinsics.h"
#include "core/motion.h"
#include "core/se2.h"
#include "core/camera.h"
#include "image/photometric.h"
#include "image/pyramid.h"
#include "track/aligner.h"
#include "track/local_plane.h"
#include "track/mounting_watch.h"
#include "track/motion_search.h"
#include "track/residual_image.h"
#include "track/warp_reduce.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::track {

// The alignment's options (levels, iterations, robust scale, damping, kernel) are the aligner's
// (aligner.h); the tracker adds keyframes and the judgement of each frame.
struct TrackerOptions : AlignerOptions {
  // With finest_level > 0: a frame that is to become the keyframe is refined down to level 0,
  // so that the chain of keyframes (what the pose drifts by) has full-resolution accuracy.
  bool refine_keyframes = false;
  // Keyframes: the live frame becomes the keyframe when the fraction of valid keyframe pixels
  // that land inside the live image, on valid pixels, falls below keyframe_overlap.
  double keyframe_overlap = 0.7;
  // ... or when the ground's linear scale in the image has changed by more than this (|log| of
  // it, anywhere in the region of interest's centre and corners; 0.1 is 10.5 %), which driving
  // along a perspective camera's viewing direction does while the overlap stays high.
  double keyframe_scale_change = 0.1;
  // Bad input. A frame interval longer than max_gap_factor times the usual interval is a gap
  // (status at best Degraded); longer than max_gap_seconds, the constant-velocity prediction is
  // not used (zero motion is). Live texture below min_texture_ratio of the keyframe's (mean
  // squared gradient over the overlap) is Lost, and so are too few valid pixels
  // (min_valid_fraction of the level's pixels; both AlignerOptions). The residual's mean square relative to the keyframe's
  // intensity variance over the overlap (about 1 for unrelated images after the brightness
  // fit; 0.02-0.1 on the simulator at 640x480, up to 0.26 at 320x240 where pixel noise
  // dominates): above lost_residual_ratio Lost, above degraded_residual_ratio Degraded.
  // Inlier fraction below min_inlier_fraction: Degraded (with k = 2 sigma of this frame's own
  // residuals, Gaussian residuals give 0.95; a heavy tail of unexplained pixels, fewer).
  // |a| > max_log_gain: Lost. Degraded when the independent-pixel covariance's (sigma^2
  // (J^T W J)^-1, with which these were measured; not the reported one) position standard
  // deviation (larger axis) exceeds max_position_std, its axes differ by more than max_std_ratio (texture
  // that constrains the motion in one direction only, e.g. stripes: 21; the shared textures:
  // 1.9-3.5), or the heading's exceeds max_heading_std (typical: 2-10 um, 1e-5 rad).
  double max_gap_factor = 2.5;
  double max_gap_seconds = 0.5;
  double lost_residual_ratio = 0.75;
  double degraded_residual_ratio = 0.5;
  double min_inlier_fraction = 0.6;
  double max_log_gain = 0.7;
  double max_position_std = 1e-4;  // metres
  double max_std_ratio = 10.0;
  double max_heading_std = 1e-3;   // radians
  // Lost when FrameResult::texture_residual (how much of the two images' texture the residual
  // still holds, texture_residual.h) exceeds this: the images do not match as aligned, whatever
  // else agreed with the alignment (a pattern fixed to the camera, such as a lamp's falloff, its
  // reflection or the robot's shadow, holds an alignment while the floor moves). Aligned frames
  // measure 0.2-0.55 on the simulator, frames held by the light 0.85-1.1 (src/track/README.md,
  // "Honest status under the camera's own light"). Infinite: not measured (no cost).
  double max_texture_residual = 0.7;
  // Covariance (src/track/README.md, "The tracker"; its measured NEES: test/bench/results/track.md). The alignment's is the M-estimator's
  // sandwich B^-1 M B^-1 (B: J^T J over the Huber inliers, M: the scores' outer product over
  // clusters of neighbouring pixels, ReduceSums::score_outer) plus (f delta)(f delta)^T, delta
  // the finest level's last Gauss-Newton step, f = covariance_step_fraction: that step is
  // applied without a pass to check it, and Gauss-Newton steps under Huber weights fall a
  // little short (0.1 measured; 0 leaves the sandwich alone).
  double covariance_step_fraction = 0.1;
  // The motion's: consecutive frames aligned with one keyframe see the same keyframe pixels,
  // so their alignment errors share a part (the keyframe's noise and interpolation), which
  // cancels in the motion between them. Modelled as the cross-covariance rho * C_{k-1} (C_{k-1}
  // carried into this frame), so the motion's covariance is C_k + (1 - 2 rho) C_{k-1}; rho
  // measured on the simulator (0 takes the alignments as independent, 0.5 drops C_{k-1}).
  double consecutive_alignment_correlation = 0.25;
  // The camera-frame path smooths level 0 before building the pyramid (ImagePipelineOptions::
  // prefilter; src/track/README.md, "The prefilter"). Pyramids given to track(Pyramid) are
  // taken as they are.
  bool prefilter = true;
  // Under the camera's light, the noise's share in the gradients is taken out
  // (ImagePipelineOptions::decorrelate_noise, image/gradient_noise.h).
  bool decorrelate_noise = true;
  // The camera-frame path takes the light fixed to the camera out of each frame before its
  // pyramid (image/photometric.h: learnt online, saturated and contrast-less pixels left out).
  // The model learns from a frame when the image has moved by at least learn_motion_px
  // (level-0 pixels, anywhere in the image) since the last frame it learnt from, by the
  // tracked motions and the constant-velocity prediction; a new model is taken into use when a
  // frame becomes the keyframe (the keyframe is corrected again with it, so that a keyframe and
  // the frames aligned with it are always corrected alike).
  PhotometricOptions photometric;
  double learn_motion_px = 8.0;
  // A known flat field instead of learning (image/photometric.h, read_flat_field: the camera's
  // relative brightness per distorted pixel, brightest 1, an 8- or 16-bit grey image file): read
  // and checked when the Tracker is made (InvalidInput naming the file), taken to the undistorted
  // image and used as the model from the first frame, without learning. Empty: learnt. Unused when
  // photometric.enabled is false.
  std::string flat_field;

  // A rolling shutter or an exposure (CameraModel::timed_rows), camera-frame path: each frame
  // is undistorted to the instantaneous global shutter's image at its stamp
  // (image/rolling_shutter.h) with the robot's twist over the frame, predicted from the frames
  // before (track/readout_twist.h). Its alignment then measures the twist; the mean offset the
  // remaining twist error puts in the frame's pose (the mean row time times the error) is taken
  // out of it, and when the two twists move the image (by the row furthest from the stamp) by
  // more than rolling_shutter_tolerance_px the frame is
  // undistorted again with the measured twist and aligned once more from half resolution (twice
  // at most): the first-order correction no longer holds there. A keyframe undistorted without a
  // measured twist (the first frame, one after a Lost frame) is undistorted again with the next
  // frame's. Pyramids given to track(Pyramid) are taken as they are.
  double rolling_shutter_tolerance_px = 1.0;

  // A frame that would be Lost after the alignments from the prediction and from the previous
  // frame (the first frames of a robot already at speed, a kick, the frames after a Lost run)
  // is searched for (motion_search.h: a grid of motions around the previous frame's pose, scored
  // at once on the coarsest level) and aligned from the search's best peaks, best first, until
  // one is not Lost. false: no search (such frames are Lost).
  bool search_motion = true;
  MotionSearchOptions search;

  // Fill FrameResult::motion_tilt_jacobian: after the alignment, one pass of the roll/pitch
  // estimator's (NPARAM 5) at half resolution (level 0 on a 320x240 camera) at the estimate; the
  // implicit function theorem on its normal equations gives d pose / d tilt (0.6-1.2 ms a frame at
  // 640x480 here). For the calibration (calib/tilt_propagation.h); off for tracking.
  bool tilt_jacobian = false;

  // The local plane (the paper's section 6.4; local_plane.h): the body's roll and pitch relative
  // to the local ground plane are estimated with every frame's motion (FrameResult::attitude), so
  // that a car's body leaning in turns or pitching over bumps does not bend the motions. The
  // extrinsics given are then the camera's mounting on the body at rest. The live attitude's
  // prior is the mounting (zero) with standard deviation local_plane_prior_sigma, radians.
  bool local_plane = false;
  double local_plane_prior_sigma = 0.5 * M_PI / 180.0;
  // Online recalibration, with the local plane (mounting_watch.h): a step in the body's attitude
  // that persists is the camera's mounting changed (a knock), reported in the frame that confirmed
  // it (FrameResult::mounting_change). Recalibrate: the mounting is changed by it (the camera
  // turned about its centre: the height is kept) and tracking carries on with it; Report: only
  // reported, the mounting given is kept; Ignore: not watched.
  enum class MountingResponse { Ignore, Report, Recalibrate };
  MountingResponse on_mounting_change = MountingResponse::Recalibrate;
  MountingWatchOptions mounting_watch;

  static WarpReduceOptions default_kernel_options();
  // Extrinsics outside what a camera on a vehicle can be (core/extrinsics.h: an offset over 20 m,
  // a height over 5 m, an angle over a turn; most likely millimetres or degrees) are refused
  // unless this is set, for an unusual rig.
  bool accept_unusual_extrinsics = false;
};

struct FrameResult {
  enum class Status {
    First,     // the first frame (or the first after reset): it becomes the keyframe, no motion
    Ok,
    Degraded,  // tracked, but something is doubtful (reason says what)
    Lost,      // not tracked: motion is the constant-velocity prediction (or zero)
  };
  Status status = Status::First;
  const char* reason = "";  // why Degraded or Lost ("" when Ok)
  // Frame-to-frame motion (core::Motion, the type the graph calibrations take): value is this
  // frame's robot pose in the previous frame's robot frame (T_{k-1}^-1 T_k, docs/conventions.md),
  // metres and radians; covariance that of the right perturbation xi in value·exp(xi), (x, y)
  // in metres, theta in radians. The motion is (T_kf^-1 T_{k-1})^-1 (T_kf^-1 T_k), its error
  // xi_k - Ad(m̂^-1) xi_{k-1}: this frame's alignment covariance plus the previous frame's
  // carried through the adjoint, less their shared part, C_k + (1 - 2 rho) Ad C_{k-1} Ad^T
  // (TrackerOptions::consecutive_alignment_correlation; just C_k when the previous frame is
  // the keyframe). Measured against the simulator's truth (README.md, "Covariance
  // (simulator)"): mean NEES of the motions about 3 over many sequences, 1-5 per sequence
  // (texture-dependent); overconfident (about 5) for frames while the robot stands still,
  // conservative (about 1.7) at walking speeds. Consecutive motions share the middle frame's
  // alignment error, so their errors are negatively correlated (about -0.4). Large (1 m^2,
  // 1 rad^2 on the diagonal) when Lost or First, and for the first frame after a Lost one that
  // did not become the keyframe.
  Motion motion{SE2(), Eigen::Matrix3d::Identity()};
  // Covariance of this frame's own alignment with the keyframe: the right perturbation of its
  // pose in the keyframe's robot frame (the estimate T_kf^-1 T_k), same units; brightness
  // marginalised (TrackerOptions::covariance_step_fraction says how it is made). Frames
  // aligned with the same keyframe share that keyframe's own part of the error (correlation
  // 0.2-0.7 between consecutive frames), which is in this covariance and cancels in the motion.
  Eigen::Matrix3d alignment_covariance = Eigen::Matrix3d::Identity();
  std::array<int, kMaxLevels> iterations{};  // fused passes per level
  std::array<double, kMaxLevels> level_ms{};  // wall time per level (passes and solves), ms
  int levels_used = 0;
  double final_cost = 0;       // mean Huber cost per valid pixel at the finest level
  double inlier_fraction = 0;  // |r| <= k among the valid pixels at the finest level
  double overlap = 0;          // valid keyframe pixels landing on valid live pixels
  double sigma = 0;            // robust residual scale at the finest level, grey levels
  double log_gain = 0, bias = 0;  // brightness relative to the keyframe
  // How much of the two images' texture the residual at the final alignment still holds
  // (texture_residual.h), measured on the pyramid level of about 160 x 120 pixels: near 0 for
  // aligned images, 1 for unrelated ones. An alignment held by a pattern fixed to the camera
  // while the floor moved leaves the floor's texture in the residual
  // (TrackerOptions::max_texture_residual). NaN when not measured.
  double texture_residual = 0;
  bool keyframe = false;       // this frame became the keyframe
  // With TrackerOptions::tilt_jacobian: d motion / d (roll, pitch) of the extrinsics the tracker
  // was given, in the right perturbation of motion.value (the covariance's coordinates) per
  // radian: how this motion would move had the tilt been different (zero otherwise, and Lost).
  Eigen::Matrix<double, 3, 2> motion_tilt_jacobian = Eigen::Matrix<double, 3, 2>::Zero();
  // With TrackerOptions::local_plane: the body's attitude relative to the local ground plane at
  // this frame, R_plane_body = Rx(roll) Ry(pitch) (core/body_attitude.h), and its covariance
  // (radians^2). A Lost frame keeps the last attitude with the prior's covariance. Zero, with a
  // zero covariance, without the local plane (the rigid body assumed).
  BodyAttitude attitude;
  Eigen::Matrix2d attitude_covariance = Eigen::Matrix2d::Zero();
  // The images separated the attitude from the motion: its variance is below half the prior's
  // (local_plane_prior_sigma^2). Not while the car has not yet moved (the attitude holds at the
  // mounting, or at the last keyframe's), nor on a Lost frame.
  bool attitude_observed = false;
  // The mounting this frame was tracked with (the extrinsics given, or the last recalibration's),
  // and, when this frame confirmed a change of it (TrackerOptions::on_mounting_change), the change:
  // its time, the step in the body's attitude with its sigma, and the mounting it implies (the
  // one in use from the next frame on when recalibrating). With the local plane only.
  Extrinsics mounting;
  bool mounting_changed = false;
  MountingChange mounting_change;
  Extrinsics changed_mounting;
  double ms = 0;               // wall time of track(), milliseconds
  double pipeline_ms = 0;      // of which the image pipeline (camera-frame API only)
};

const char* status_name(FrameResult::Status s);

class Tracker {
 public:
  // The camera's undistorted pinhole model (K, width, height) and the extrinsics. Builds the
  // kernels; allocates the keyframe pyramid on the first frame.
  Tracker(ocl::Runtime& runtime, const CameraModel& camera, const Extrinsics& extrinsics,
          const TrackerOptions& options = {});
  ~Tracker();
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;

  // Tracks one camera frame: 8-bit grey, width x height (the camera's size), rows `stride`
  // bytes apart, timestamp in seconds. The image pipeline (image/pipeline.h: upload,
  // undistortion, pyramid, gradients; created on the first frame) fills one of two device
  // pyramids that the tracker swaps with the keyframe's, so nothing is copied. A frame of
  // another size is Lost (not an exception); a null image or stride < width is
  // InvalidArgument.
  FrameResult track(const uint8_t* gray, int width, int height, size_t stride, double timestamp);

  // Tracks one frame's device pyramid made elsewhere (pyramid.h: level 0 of the camera's
  // size; options.levels levels, or as many as it has). The pyramid is only read; when the
  // frame becomes the keyframe its levels are copied on the device. A pyramid of another
  // size is Lost.
  FrameResult track(const Pyramid& live, double timestamp);

  // The last frame's residual image against the keyframe it was aligned with (residual_image.h),
  // at pyramid `level` (0: full resolution), every pixel of the level whatever subsampling
  // tracking used: the final alignment's warp for that level, its brightness, and the Huber
  // threshold k of the finest level tracked (huber_factor times the robust scale in use there,
  // AlignmentReport::finest_huber_k). One extra pass of the fused kernel's DEBUG_OUTPUT variant,
  // made on request only (built on the first); asking again for the same level before the next
  // frame costs nothing. A frame that became the keyframe is still compared with the keyframe
  // it was aligned with. A Lost frame whose alignment ran (its images judged not to match, or
  // its brightness) has its residuals at that alignment; for one without an alignment (wrong
  // size, too few valid pixels, no live texture, diverged) this is Error(Failed) with the
  // reason. InvalidArgument before any frame was aligned after the first (or after reset()),
  // or for a level out of range. With track(Pyramid), the live pyramid must still hold the frame.
  ResidualImage residuals(int level = 0);

  // The wheel odometry's pose at the frame about to be tracked (any fixed odometry frame), before
  // track(): with the local plane, the mounting watch compares the distances tracked with the
  // wheels' to find the camera's height changed (mounting_watch.h). Frames given none are left out
  // of that comparison.
  void set_odometry(const SE2& pose);

  // Forgets the keyframe, the pose, the velocity and the residual scales.
  void reset();
  // The accumulated robot pose relative to the first frame (product of the motions).
  const SE2& pose() const;
  const TrackerOptions& options() const;
  // The photometric model in use (its scale and offset per undistorted pixel), for saving it
  // (flat_field_to_distorted, write_flat_field): the known flat field's, or the learnt one; null
  // while it is the identity (no frame yet, photometric off, or not yet learnt: the model stays
  // the identity until the statistics or the alignments show light fixed to the camera). Valid
  // until the next call to track().
  const PhotometricFit* photometric_model() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace planarvo::track
