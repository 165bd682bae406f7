// The camera's roll and pitch from images alone (paper section 5.1, eqs. 14-24): a local dense
// map of keyframes, the planar motions between consecutive keyframes and the camera's
// orientation to the ground estimated jointly by the one aligner (aligner.h) with the camera at
// x = y = 0, z = 1, yaw = 0 (eq. 14), so the motions are the camera's own planar motions in
// units of its height.
//
// Frames are fed one at a time. A tracker at the initial orientation picks the keyframes (a frame
// joins the map when its overlap with the last keyframe falls below keyframe_overlap) and gives
// each keyframe pair its first motion; estimate() then aligns all pairs jointly, coarse to fine,
// repeated from its own result until the orientation stops moving, with a coarse search over
// the two angles when that does not converge.
//
// Which motions determine the tilt. Between two views of the ground, x_l ~ K (R - t n^T / z)
// K^-1 x_r. A translation t of the camera over the ground determines n: t n^T has 4 degrees of
// freedom (t in the plane, n of unit length), with an information that grows with |t| / z and
// the field of view. A camera that only rotates (turning about the vertical through its own
// centre; for a camera looking straight down, about its optical axis) sees K R_n(theta) K^-1,
// a rotation about the ground normal itself: the image turns about the point K n, which
// determines n for any rotation that is not small (measured: 0.2 rad between keyframes, 0.002
// degrees of error, sigma 0.007 degrees; the test RollPitch.TurningAboutTheCamera...). So the
// only degenerate motion is none at all (standing still), and weak ones are small rotations
// without translation. estimate() refuses (TooLittleMotion) when the map's camera motion, in
// camera heights of translation plus radians of rotation summed over its pairs, is below
// min_motion, or when the estimated standard deviation of roll or pitch exceeds max_sigma.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/se2.h"
#include "core/camera.h"
#include "image/photometric.h"
#include "track/aligner.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::track {

struct RollPitchOptions {
  // The joint alignment, down to full resolution (the tilt is a small effect: the finest level
  // decides its accuracy).
  AlignerOptions align = default_align();
  // Start of the estimate: a camera looking straight down unless given (radians).
  double initial_roll = 0.0, initial_pitch = 0.0;
  // The light fixed to the camera (image/photometric.h): learnt from the frames in which the floor
  // moved (by the tracked motions, or by the texture left in the residual: track/texture_residual.h,
  // which a lamp holding the tracker at "no motion" leaves), fitted once when a refit is first due
  // (30 frames), and, when it is not the identity, the map started again with it. An evenly lit
  // camera keeps the identity, and its frames are what they were without the model.
  PhotometricOptions photometric;
  // When a light was found, the map is complete only once the model's statistics hold
  // light_frames frames in motion (or max_frames is reached): the model is then fitted again
  // from all of them and every keyframe corrected with it before the joint alignment
  // (the 30-frame model's noise pulls the orientation; src/calib/README.md).
  int light_frames = 120;
  // The map: a frame becomes a keyframe when its overlap with the last one falls below this
  // (0.9: pairs a tenth of the view apart; at 0.7, a tilted camera's pairs span more than a camera
  // height, near and far field swap resolution between the two views and the pairs stop aligning,
  // measured on the simulator at 30 degrees of roll); the estimate needs min_keyframes (5 to 50 in the paper) and the map stops growing at
  // max_keyframes. max_frames > 0 stops it after that many frames counted from the first frame
  // in which the camera moved (a standing start costs nothing); 0: no limit but max_keyframes.
  double keyframe_overlap = 0.9;
  int min_keyframes = 5;
  int max_keyframes = 12;
  int max_frames = 0;
  // Joint alignments from the previous one's result until roll and pitch move less than this
  // (radians), at most max_rounds.
  int max_rounds = 4;
  double round_tolerance = 1e-5;
  // A rolling shutter: the keyframes undistorted again with the measured motion and aligned again
  // until roll and pitch move less than unroll_tolerance (radians), at most max_unrolls times.
  int max_unrolls = 6;
  double unroll_tolerance = 1e-4;
  // The keyframes are aligned band-passed (image/band_pass.h): sigma at full resolution, level
  // pixels; 0: as the pipeline made them. Under a lamp, a reflection and a shadow the light
  // model's remaining error otherwise pulls roll by up to 1.5 degrees on a faint floor; on
  // evenly lit drives it changes roll and pitch by under 0.02 degrees (src/calib/README.md).
  double band_pass_sigma = 2.5;
  // A pair does not align when its residual's mean square stays above search_residual_ratio of
  // its keyframe's intensity variance (the tracker's "images do not match" level: unaligned pairs
  // measured 1.0-2.5; aligned ones 0.03-0.12 on textured floors and up to 0.48 on a low-texture
  // floor under 2.5 grey levels of noise, where noise is a large part of the variance). Such
  // pairs leave the map; when none aligns, the alignment is started again from each point of a
  // grid of roll and pitch within search_range of the initial orientation, search_step apart,
  // and the lowest residual wins.
  bool search = true;
  double search_range = 0.6, search_step = 0.3;  // radians
  double search_residual_ratio = 0.75;
  // Covariance: inflation^2 sigma^2 S^-1, S the orientation's information with every pair's
  // motion and brightness marginalised, sigma^2 the weighted residual variance (at least
  // align.min_sigma^2). The residuals are not independent from pixel to pixel (interpolation,
  // the pyramid's smoothing, texture the renderer and the lens blur alike), so sigma^2 S^-1 is
  // optimistic: over 15 simulated 640x480 drives (3 textures, 5 camera poses) the RMS of error /
  // sigma was 1.95 for roll and 4.90 for pitch without inflation; 3 (in standard deviation) makes
  // it 0.65 and 1.63 (src/calib/README.md).
  double covariance_inflation = 3.0;
  // Plus what the jackknife's over the pairs has beyond it (the positive part of their
  // difference): the analytic one misses what differs from pair to pair. Under a lamp, a reflection, a
  // shadow and a rolling shutter it claimed 3-14 times too little (brick_floor: 0.025 degrees
  // off with sigma 0.003); on an evenly lit drive the two agree (src/calib/README.md).
  bool jackknife = true;
  // Refusals: too little motion when the camera's motion summed over the pairs (camera heights of
  // translation plus radians of rotation) is below min_motion, or a standard deviation of roll
  // or pitch above max_sigma.
  double min_motion = 0.2;
  double max_sigma = 0.5 * 3.14159265358979 / 180.0;

  static AlignerOptions default_align();
};

struct RollPitchResult {
  enum class Status {
    Ok,
    TooLittleTexture,  // the frames could not be tracked: no texture on the ground
    TooLittleMotion,   // the camera did not translate enough over the ground
    Failed,            // the joint alignment failed (reason says how)
  };
  Status status = Status::Failed;
  std::string reason;  // "" when Ok; otherwise what went wrong and what would fix it
  double roll = 0.0, pitch = 0.0;  // radians (docs/conventions.md)
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  // of (roll, pitch), rad^2
  int frames_used = 0;   // frames fed before the map was complete
  int keyframes = 0;
  int pairs = 0;         // keyframe pairs in the estimate (consecutive keyframes that align)
  int rounds = 0;        // joint alignments run (search included)
  int unrolls = 0;       // a rolling shutter: times the keyframes were undistorted again
  int passes = 0;        // fused passes of the joint alignments
  double motion = 0.0;  // the camera's motion summed over the pairs: heights of translation + radians
  double residual_ratio = 0.0;  // worst pair's residual mean square over its keyframe's variance
  // The jackknife's covariance over the pairs (RollPitchOptions::jackknife; zero when off or
  // fewer than 3 pairs), rad^2.
  Eigen::Matrix2d jackknife_covariance = Eigen::Matrix2d::Zero();
  double track_ms = 0.0, align_ms = 0.0;  // picking the keyframes, the joint alignment
  // The map: which frames (0-based, in the order fed) are its keyframes, and the camera's planar
  // motion of each pair in the estimate (reference keyframe index, live keyframe index, motion in
  // units of the camera height).
  std::vector<int> keyframe_frames;
  struct Pair {
    int reference = 0, live = 0;
    SE2 motion;
  };
  std::vector<Pair> pair_motions;
  bool ok() const { return status == Status::Ok; }
};

const char* status_name(RollPitchResult::Status s);

class RollPitchEstimator {
 public:
  // camera: the distorted camera the frames come from (the image pipeline undistorts them).
  RollPitchEstimator(ocl::Runtime& runtime, const CameraModel& camera, const RollPitchOptions& options = {});
  ~RollPitchEstimator();
  RollPitchEstimator(const RollPitchEstimator&) = delete;
  RollPitchEstimator& operator=(const RollPitchEstimator&) = delete;

  // Feeds one frame (8-bit grey, the camera's size, rows stride bytes apart; timestamp in
  // seconds). Returns true once the map is complete; later frames are ignored. A frame of the
  // wrong size or without texture is counted and skipped, as the tracker does.
  bool add_frame(const uint8_t* gray, int width, int height, size_t stride, double timestamp);
  bool complete() const;
  int keyframes() const;

  // Estimates roll and pitch from the map (any number of keyframes; fewer than min_keyframes
  // is TooLittleMotion or TooLittleTexture with the reason).
  RollPitchResult estimate();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace planarvo::track
