#include "core/extrinsics.h"

#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Geometry>

#include "core/error.h"

namespace planarvo {

Eigen::Matrix3d Extrinsics::R0() {
  Eigen::Matrix3d r;
  r << 0, -1, 0, -1, 0, 0, 0, 0, -1;
  return r;
}

Eigen::Matrix3d Extrinsics::R_vc() const {
  using Eigen::AngleAxisd;
  using Eigen::Vector3d;
  return (AngleAxisd(yaw, Vector3d::UnitZ()) * AngleAxisd(pitch, Vector3d::UnitY()) *
          AngleAxisd(roll, Vector3d::UnitX()))
             .toRotationMatrix() *
         R0();
}

Eigen::Matrix4d Extrinsics::T_vc() const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R_vc();
  T.topRightCorner<3, 1>() = t_vc();
  return T;
}

Eigen::Vector3d Extrinsics::plane_normal_camera() const {
  return R_vc().transpose() * Eigen::Vector3d::UnitZ();
}

Extrinsics Extrinsics::from_matrix(const Eigen::Matrix4d& T) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if (!((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6) ||
      !(std::abs(R.determinant() - 1.0) < 1e-6))
    throw_invalid_argument("T_robot_camera: rotation part is not orthonormal with determinant 1");
  // M = Rz(yaw) Ry(pitch) Rx(roll) (R0 is its own inverse).
  const Eigen::Matrix3d M = R * R0().transpose();
  Extrinsics e;
  e.pitch = std::asin(std::max(-1.0, std::min(1.0, -M(2, 0))));
  e.roll = std::atan2(M(2, 1), M(2, 2));
  e.yaw = std::atan2(M(1, 0), M(0, 0));
  e.x = T(0, 3);
  e.y = T(1, 3);
  e.z = T(2, 3);
  return e;
}

Eigen::Matrix3d ground_homography(const Eigen::Matrix3d& K, const Extrinsics& e,
                                  const Eigen::Matrix4d& robot_motion) {
  // Camera motion from reference to live, X_l = R X_r + t: T_cl_cr = T_cv * T_vl_vr * T_vc with
  // T_vl_vr = motion^-1 (the motion is the live pose in the reference robot frame).
  const Eigen::Matrix4d T_vc = e.T_vc();
  const Eigen::Matrix4d T_lr = T_vc.inverse() * robot_motion.inverse() * T_vc;
  const Eigen::Matrix3d R = T_lr.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_lr.topRightCorner<3, 1>();
  const Eigen::Vector3d n = e.plane_normal_camera();
  const Eigen::Matrix3d H = K * (R - t * n.transpose() / e.z) * K.inverse();
  return H / H(2, 2);
}

Eigen::Matrix3d ground_homography(const Eigen::Matrix3d& K, const Extrinsics& e_ref, const Extrinsics& e_live,
                                  const Eigen::Matrix4d& robot_motion) {
  // X_l = T_cl_cr X_r with T_cl_cr = T_cv(live) * motion^-1 * T_vc(ref).
  const Eigen::Matrix4d T_lr = e_live.T_vc().inverse() * robot_motion.inverse() * e_ref.T_vc();
  const Eigen::Matrix3d R = T_lr.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_lr.topRightCorner<3, 1>();
  const Eigen::Vector3d n = e_ref.plane_normal_camera();
  const Eigen::Matrix3d H = K * (R - t * n.transpose() / e_ref.z) * K.inverse();
  return H / H(2, 2);
}

namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string length_problem(const char* name, double v, double limit, const char* what) {
  std::string s = std::string(name) + " = " + number(v) + " m is " + what + " " + number(limit) + " m";
  if (std::abs(v) / 1000.0 <= limit && v != 0.0)
    s += ": millimetres by mistake? (" + number(v) + " mm = " + number(v / 1000.0) + " m)";
  return s;
}

}  // namespace

std::string implausible_extrinsics(const Extrinsics& e, bool height_given) {
  if (!e.finite()) return "a value is not a finite number";
  if (std::abs(e.x) > kMaxOffset) return length_problem("x", e.x, kMaxOffset, "more than");
  if (std::abs(e.y) > kMaxOffset) return length_problem("y", e.y, kMaxOffset, "more than");
  if (e.z > kMaxHeight) return length_problem("the height z", e.z, kMaxHeight, "over");
  if (e.z < 0.0 || (height_given && e.z == 0.0))
    return "the height z = " + number(e.z) + " m is not above the ground (z is the camera's height, positive)";
  const struct {
    const char* name;
    double value;
  } angles[] = {{"roll", e.roll}, {"pitch", e.pitch}, {"yaw", e.yaw}};
  for (const auto& a : angles)
    if (std::abs(a.value) > 2.0 * M_PI)
      return std::string(a.name) + " = " + number(a.value) + " rad is more than a turn: degrees by mistake? (" +
             number(a.value) + " deg = " + number(a.value * M_PI / 180.0) + " rad)";
  return "";
}

void check_plausible_extrinsics(const Extrinsics& e, const std::string& what, bool height_given) {
  const std::string why = implausible_extrinsics(e, height_given);
  if (!why.empty())
    throw_invalid_argument(what + ": " + why +
                           " (angles are radians, lengths metres; for an unusual rig set accept_unusual_extrinsics, "
                           "--force in the planarvo tool)");
}

void check_plausible_height(double z, const std::string& what) {
  check_plausible_extrinsics(Extrinsics{0.0, 0.0, z, 0.0, 0.0, 0.0}, what);
}

}  // namespace planarvo
