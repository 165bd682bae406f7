// A planar relative motion with its uncertainty: what the tracker measures per frame and what the
// graph calibrations consume (sensor motions, wheel odometry), in one type so that neither has to
// convert the other's covariance convention.
#pragma once
#include <cmath>

#include <Eigen/Core>

#include "core/se2.h"

namespace planarvo {

struct Motion {
  SE2 value;
  // Covariance of the right perturbation xi = (x, y, theta) in value·exp(xi): x and y in the
  // motion's units (metres, or units of the camera height for the tracker run at height 1),
  // theta in radians; so the translation block is in the frame at the motion's end, not the
  // frame the motion is expressed in. Zero means "not given" (a consumer then uses its own
  // noise model).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();

  bool has_covariance() const { return !(covariance.array() == 0.0).all(); }
};

// The covariance of value's (x, y, theta) taken as three numbers, to first order: value·exp(xi)
// moves them by (R(theta) xi_xy, xi_theta), so it is A covariance Aᵀ with A = diag(R(theta), 1).
inline Eigen::Matrix3d component_covariance(const Motion& m) {
  const double c = std::cos(m.value.theta), s = std::sin(m.value.theta);
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  A(0, 0) = c; A(0, 1) = -s;
  A(1, 0) = s; A(1, 1) = c;
  return A * m.covariance * A.transpose();
}

}  // namespace planarvo
