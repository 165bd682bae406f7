#include "track/local_plane.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace planarvo::track {

void LocalPlane::reset() {
  keyframe_ = BodyAttitude();
  keyframe_cov_ = prior_covariance();
}

void LocalPlane::prepare(const BodyAttitude& live_start, AlignmentPair* pair) const {
  pair->reference_attitude = keyframe_;
  pair->live_attitude = live_start;
  pair->attitude_prior_mean << keyframe_.roll, keyframe_.pitch, 0.0, 0.0;
  pair->attitude_prior_information.setZero();
  pair->attitude_prior_information.topLeftCorner<2, 2>() = keyframe_cov_.inverse();
  pair->attitude_prior_information.bottomRightCorner<2, 2>() = prior_covariance().inverse();
}

void LocalPlane::take_keyframe(const BodyAttitude& attitude, const Eigen::Matrix2d& covariance) {
  keyframe_ = attitude;
  const Eigen::LLT<Eigen::Matrix2d> llt(covariance);
  const bool usable = covariance.allFinite() && llt.info() == Eigen::Success;
  keyframe_cov_ = usable ? covariance : prior_covariance();
}

}  // namespace planarvo::track
