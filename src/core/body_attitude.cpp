#include "core/body_attitude.h"

#include <algorithm>
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

BodyAttitude attitude_of(const Eigen::Matrix3d& R) {
  // R = Rz(yaw) Rx(r) Ry(p): the third row, the plane's normal in the body's axes, is
  // (-cos r sin p, sin r, cos r cos p) whatever the yaw.
  BodyAttitude a;
  a.roll = std::asin(std::clamp(R(2, 1), -1.0, 1.0));
  a.pitch = std::atan2(-R(2, 0), R(2, 2));
  return a;
}

Extrinsics turned_mounting(const Extrinsics& mounting, const BodyAttitude& step, double yaw) {
  Eigen::Matrix4d T = mounting.T_vc();
  T.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * step.R_plane_body() * mounting.R_vc();
  return Extrinsics::from_matrix(T);
}

BodyAttitude relative_to_turned(const BodyAttitude& a, const BodyAttitude& step, double yaw) {
  return attitude_of(a.R_plane_body() * step.R_plane_body().transpose() *
                     Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix());
}

}  // namespace planarvo
