#include "track/light_learning.h"

#include "track/warp_model.h"

namespace planarvo::track {

LightLearningGate::LightLearningGate(const Eigen::Matrix3d& K, int width, int height, const Extrinsics& extrinsics,
                                     double learn_motion_px, double max_texture_residual)
    : K_(K),
      width_(width),
      height_(height),
      extrinsics_(extrinsics),
      learn_motion_px_(learn_motion_px),
      max_texture_residual_(max_texture_residual) {}

bool LightLearningGate::learn_from(const FrameResult& r) {
  const bool tracked = r.status == FrameResult::Status::Ok || r.status == FrameResult::Status::Degraded;
  if (tracked) since_ = since_ * r.motion.value;
  const bool moved =
      tracked && max_pixel_displacement(K_, extrinsics_, SE2(), since_, width_, height_) >= learn_motion_px_;
  const bool texture_left = r.texture_residual > max_texture_residual_;
  if (!moved && !texture_left) return false;
  learnt();
  return true;
}

}  // namespace planarvo::track
