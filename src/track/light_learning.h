// When the photometric model (image/photometric.h) learns from a tracked frame: when the floor
// moved since the last frame it learnt from, by learn_motion_px level-0 pixels anywhere in the
// image by the motions tracked since, or, whatever the alignment says, by the floor's texture the
// alignment left in its residual (FrameResult::texture_residual above the honest-status check's
// threshold). A light fixed to the camera can hold an alignment at "no motion" while the floor
// moves, and must not keep the model from learning it; a robot standing still moves neither.
// The tracker's camera-frame path and the roll/pitch estimator's map both learn by it.
#pragma once
#include <Eigen/Core>

#include "core/extrinsics.h"
#include "core/se2.h"
#include "track/tracker.h"

namespace planarvo::track {

class LightLearningGate {
 public:
  // The camera's undistorted K and size, the extrinsics the motions are tracked with, and the two
  // thresholds (TrackerOptions::learn_motion_px and max_texture_residual).
  LightLearningGate(const Eigen::Matrix3d& K, int width, int height, const Extrinsics& extrinsics,
                    double learn_motion_px, double max_texture_residual);

  // Whether the model learns from this frame (the motion then counts from it).
  bool learn_from(const FrameResult& r);
  // The model learnt from the current frame otherwise (the first frame, one learnt from at once):
  // the motion counts from it.
  void learnt() { since_ = SE2(); }

 private:
  Eigen::Matrix3d K_;
  int width_, height_;
  Extrinsics extrinsics_;
  double learn_motion_px_, max_texture_residual_;
  SE2 since_;  // the motion since the last frame learnt from
};

}  // namespace planarvo::track
