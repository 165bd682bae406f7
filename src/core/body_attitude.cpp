#include "core/body_attitude.h"

#include <cmath>

#include <Eigen/Geometry>

namespace planarvo {

Eigen::Matrix3d BodyAttitude::R_plane_body() const {
  return (Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}

Extrinsics on_plane(const Extrinsics& mounting, const BodyAttitude& a) {
  if (a.zero()) return mounting;
  Eigen::Matrix4d B = Eigen::Matrix4d::Identity();
  B.topLeftCorner<3, 3>() = a.R_plane_body();
  return Extrinsics::from_matrix(B * mounting.T_vc());
}

}  // namespace planarvo
