// The local plane (the paper's section 6.4): a car's body rolls in turns and pitches over bumps,
// so the camera's orientation to the road changes from frame to frame. The tracker then aligns
// with the body's attitude relative to the local ground plane as part of the state
// (AlignerModel::LocalPlane, warp_model.h's local_plane_homography): the keyframe's and the live
// frame's roll and pitch with the planar motion, seven parameters, in the one aligner.
//
// Why both attitudes. The live attitude against the keyframe's is what the images measure
// sharply (the camera's rotation between the views); where the body stands relative to the plane
// shows only through the plane's normal in the keyframe's view (the t n^T / z part of the
// homography), as in the roll/pitch calibration (section 5.1). With the keyframe's attitude held
// fixed at its estimate, its error would pass unchanged from keyframe to keyframe (a random walk);
// estimated with a Gaussian prior from its own estimate (when it was the live frame), the normal
// corrects it while the relative rotation carries it on: a Kalman filter along the keyframes,
// whose prediction is that the body keeps its attitude, and whose measurement is the alignment.
// The live attitude's prior is the calibration (zero) with sigma prior_sigma: it holds the
// attitude where the images say nothing (standing still: the attitude stays at the keyframe's).
//
// The paper's alternative, one attitude for the five most recent frames, cannot follow a body
// that pitches by 10 degrees over a bump within a second (2.6 degrees between frames at 3 m/s).
#pragma once
#include <Eigen/Core>

#include "core/body_attitude.h"
#include "track/aligner.h"

namespace planarvo::track {

class LocalPlane {
 public:
  explicit LocalPlane(double prior_sigma = 0.05) : prior_sigma_(prior_sigma) { reset(); }

  // The body at the calibration (attitude zero), known to prior_sigma.
  void reset();

  // A pair about to be aligned: the keyframe's attitude with its prior from its estimate, the
  // live attitude from `live_start` with the calibration's prior.
  void prepare(const BodyAttitude& live_start, AlignmentPair* pair) const;

  // The live frame became the keyframe: its attitude and covariance (radians^2) are the
  // keyframe's from now on. A covariance that is not finite or not positive definite is taken as
  // the prior's.
  void take_keyframe(const BodyAttitude& attitude, const Eigen::Matrix2d& covariance);

  // The mounting was turned by `step` and `yaw` (core/body_attitude.h, turned_mounting): the
  // keyframe's attitude re-expressed against it, its covariance kept.
  void mounting_turned(const BodyAttitude& step, double yaw) { keyframe_ = relative_to_turned(keyframe_, step, yaw); }

  const BodyAttitude& keyframe() const { return keyframe_; }
  const Eigen::Matrix2d& keyframe_covariance() const { return keyframe_cov_; }
  // The prior's covariance (prior_sigma^2 I): where nothing else is known (a Lost frame's).
  Eigen::Matrix2d prior_covariance() const { return prior_sigma_ * prior_sigma_ * Eigen::Matrix2d::Identity(); }

 private:
  double prior_sigma_;
  BodyAttitude keyframe_;
  Eigen::Matrix2d keyframe_cov_;
};

}  // namespace planarvo::track
