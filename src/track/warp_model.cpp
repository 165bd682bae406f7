#include "track/warp_model.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>

namespace planarvo::track {

namespace {

// top3(T) P: the 3x3 map from a ground point's camera coordinates to the moved point, for a
// 4x4 camera motion T (docs/conventions.md: R - t n^T / z).
Eigen::Matrix3d plane_map(const Eigen::Matrix4d& T, const Eigen::Vector3d& n, double z) {
  return T.topLeftCorner<3, 3>() - T.topRightCorner<3, 1>() * n.transpose() / z;
}

// [v]_x, the cross-product matrix.
Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// The 4x4 generator of se(2) raised to the plane z = 0 for SE2::exp's coordinate i: translation
// along x, along y, rotation about z.
Eigen::Matrix4d planar_generator(int i) {
  Eigen::Matrix4d gen = Eigen::Matrix4d::Zero();
  if (i == 0) gen(0, 3) = 1.0;
  if (i == 1) gen(1, 3) = 1.0;
  if (i == 2) {
    gen(0, 1) = -1.0;
    gen(1, 0) = 1.0;
  }
  return gen;
}

// Parameter k's derivative from dHu, the derivative of the unnormalised homography Hu: divided by
// s = Hu(2,2) with the quotient rule (out->H = Hu / s), and its reference-side generator.
void set_derivative(int k, const Eigen::Matrix3d& dHu, const Eigen::Matrix3d& Hu, double s,
                    const Eigen::Matrix3d& Hinv, MotionHomography* out) {
  const auto i = static_cast<size_t>(k);
  out->dH[i] = dHu / s - Hu * dHu(2, 2) / (s * s);
  out->G[i] = Hinv * out->dH[i];
}

}  // namespace

MotionHomography motion_homography(const Eigen::Matrix3d& K, const Extrinsics& e,
                                   const SE2& motion, bool with_orientation) {
  const Eigen::Matrix4d T_vc = e.T_vc();
  Eigen::Matrix4d T_cv = Eigen::Matrix4d::Identity();
  T_cv.topLeftCorner<3, 3>() = T_vc.topLeftCorner<3, 3>().transpose();
  T_cv.topRightCorner<3, 1>() = -T_cv.topLeftCorner<3, 3>() * T_vc.topRightCorner<3, 1>();
  const Eigen::Matrix4d right = motion.inverse().matrix3d() * T_vc;  // T̂^-1 T_vc
  const Eigen::Vector3d n = e.plane_normal_camera();
  const Eigen::Matrix3d Kinv = K.inverse();

  const Eigen::Matrix3d Hu = K * plane_map(T_cv * right, n, e.z) * Kinv;
  const double s = Hu(2, 2);
  MotionHomography out;
  out.H = Hu / s;
  const Eigen::Matrix3d Hinv = out.H.inverse();
  for (int i = 0; i < kMotionParams; ++i) {
    // d/dx_i exp(-x) at 0 = -gen_i. plane_map is linear in T, so its derivative is plane_map of
    // the derivative (the translation part of a 4x4 derivative enters the same way).
    const Eigen::Matrix4d dT = T_cv * (-planar_generator(i)) * right;
    set_derivative(i, K * plane_map(dT, n, e.z) * Kinv, Hu, s, Hinv, &out);
  }
  if (!with_orientation) return out;
  // Eqs. 21-24 (header comment): the tilt about the robot's x and y axes through the camera centre.
  out.nparam = kMotionParams + kOrientationParams;
  const Eigen::Matrix4d T_inv = motion.inverse().matrix3d();
  const Eigen::Matrix4d M = T_cv * right;
  const Eigen::Vector3d t = e.t_vc();
  const Eigen::Matrix3d R_cv = T_cv.topLeftCorner<3, 3>();
  for (int i = 0; i < kOrientationParams; ++i) {
    const Eigen::Matrix3d Gi = skew(Eigen::Vector3d::Unit(i));
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    A.topLeftCorner<3, 3>() = Gi;
    A.topRightCorner<3, 1>() = -Gi * t;
    const Eigen::Matrix4d dM = T_cv * (T_inv * A - A * T_inv) * T_vc;
    const Eigen::Vector3d dn = -R_cv * Gi * Eigen::Vector3d::UnitZ();
    const Eigen::Matrix3d dP = plane_map(dM, n, e.z) - M.topRightCorner<3, 1>() * dn.transpose() / e.z;
    set_derivative(kMotionParams + i, K * dP * Kinv, Hu, s, Hinv, &out);
  }
  return out;
}

MotionHomography local_plane_homography(const Eigen::Matrix3d& K, const Extrinsics& mounting, const SE2& motion,
                                        const BodyAttitude& reference, const BodyAttitude& live) {
  const Eigen::Matrix4d T_vc = mounting.T_vc();
  const Eigen::Matrix4d T_cv = T_vc.inverse();
  auto body = [](const Eigen::Matrix3d& R) {
    Eigen::Matrix4d B = Eigen::Matrix4d::Identity();
    B.topLeftCorner<3, 3>() = R;
    return B;
  };
  const Eigen::Matrix3d Br = reference.R_plane_body(), Bl = live.R_plane_body();
  const Eigen::Matrix4d E_r = body(Br) * T_vc;
  const Eigen::Matrix4d El_inv = T_cv * body(Bl.transpose());
  const Eigen::Matrix4d T_inv = motion.inverse().matrix3d();
  const Eigen::Matrix4d M = El_inv * T_inv * E_r;
  const Eigen::Matrix3d R_vc = T_vc.topLeftCorner<3, 3>();
  const Eigen::Vector3d t_vc = T_vc.topRightCorner<3, 1>();
  const Eigen::Vector3d n = R_vc.transpose() * Br.transpose() * Eigen::Vector3d::UnitZ();
  const double z = (Br * t_vc).z();
  const Eigen::Matrix3d Kinv = K.inverse();

  const Eigen::Matrix3d Hu = K * plane_map(M, n, z) * Kinv;
  const double s = Hu(2, 2);
  MotionHomography out;
  out.nparam = kMotionParams + kAttitudeParams;
  out.H = Hu / s;
  const Eigen::Matrix3d Hinv = out.H.inverse();
  auto put = [&](int k, const Eigen::Matrix3d& dP) { set_derivative(k, K * dP * Kinv, Hu, s, Hinv, &out); };
  for (int i = 0; i < kMotionParams; ++i) put(i, plane_map(El_inv * (-planar_generator(i)) * T_inv * E_r, n, z));
  // dB/droll = [e_x]_x B, dB/dpitch = B [e_y]_x.
  const Eigen::Matrix3d ex = skew(Eigen::Vector3d::UnitX()), ey = skew(Eigen::Vector3d::UnitY());
  const Eigen::Matrix3d dBr[2] = {ex * Br, Br * ey}, dBl[2] = {ex * Bl, Bl * ey};
  for (int i = 0; i < 2; ++i) {
    Eigen::Matrix4d dBr4 = Eigen::Matrix4d::Zero();
    dBr4.topLeftCorner<3, 3>() = dBr[i];
    const Eigen::Matrix4d dM = El_inv * T_inv * dBr4 * T_vc;
    const Eigen::Vector3d dn = R_vc.transpose() * dBr[i].transpose() * Eigen::Vector3d::UnitZ();
    const double dz = (dBr[i] * t_vc).z();
    const Eigen::Vector3d Mt = M.topRightCorner<3, 1>();
    put(kMotionParams + i, plane_map(dM, n, z) - Mt * dn.transpose() / z + Mt * n.transpose() * dz / (z * z));
  }
  for (int i = 0; i < 2; ++i) {
    Eigen::Matrix4d dBl4 = Eigen::Matrix4d::Zero();
    dBl4.topLeftCorner<3, 3>() = dBl[i].transpose();
    put(kMotionParams + 2 + i, plane_map(T_cv * dBl4 * T_inv * E_r, n, z));
  }
  return out;
}

Extrinsics rotate_orientation(const Extrinsics& e, const Eigen::Vector2d& y) {
  Eigen::Matrix4d T = e.T_vc();
  const Eigen::Vector3d w(y.x(), y.y(), 0.0);
  const double angle = w.norm();
  if (angle > 0.0)
    T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix() * T.topLeftCorner<3, 3>();
  return Extrinsics::from_matrix(T);
}

double max_pixel_displacement(const Eigen::Matrix3d& K, const Extrinsics& e, const SE2& a,
                              const SE2& b, int width, int height) {
  return max_pixel_displacement(K, e, a, e, b, width, height);
}

double max_pixel_displacement(const Eigen::Matrix3d& K, const Extrinsics& ea, const SE2& a,
                              const Extrinsics& eb, const SE2& b, int width, int height) {
  return max_pixel_displacement(ground_homography(K, ea, a.matrix3d()), ground_homography(K, eb, b.matrix3d()),
                                width, height);
}

double max_pixel_displacement(const Eigen::Matrix3d& Ha, const Eigen::Matrix3d& Hb, int width, int height) {
  const double w = width - 1.0, h = height - 1.0;
  const double pts[5][2] = {{0, 0}, {w, 0}, {0, h}, {w, h}, {0.5 * w, 0.5 * h}};
  double worst = 0.0;
  for (const auto& p : pts) {
    const Eigen::Vector3d q(p[0], p[1], 1.0);
    const Eigen::Vector3d qa = Ha * q, qb = Hb * q;
    const double d = (qa.hnormalized() - qb.hnormalized()).norm();
    worst = std::max(worst, std::isfinite(d) ? d : 1e30);
  }
  return worst;
}

double log_scale_change(const Eigen::Matrix3d& K, const Extrinsics& extrinsics, const SE2& motion,
                        const PixelRegion& r) {
  const Eigen::Matrix3d H = ground_homography(K, extrinsics, motion.matrix3d());
  double worst = 0.0;
  const double xs[3] = {static_cast<double>(r.x), r.x + 0.5 * (r.width - 1), static_cast<double>(r.x + r.width - 1)};
  const double ys[3] = {static_cast<double>(r.y), r.y + 0.5 * (r.height - 1), static_cast<double>(r.y + r.height - 1)};
  for (double u : xs)
    for (double v : ys) {
      const Eigen::Vector3d q = H * Eigen::Vector3d(u, v, 1.0);
      if (!(q.z() > 0.0)) return HUGE_VAL;
      const double wu = q.x() / q.z(), wv = q.y() / q.z();
      const double d00 = (H(0, 0) - wu * H(2, 0)) / q.z(), d01 = (H(0, 1) - wu * H(2, 1)) / q.z();
      const double d10 = (H(1, 0) - wv * H(2, 0)) / q.z(), d11 = (H(1, 1) - wv * H(2, 1)) / q.z();
      const double det = d00 * d11 - d01 * d10;
      if (!(det > 0.0)) return HUGE_VAL;
      worst = std::max(worst, std::abs(0.5 * std::log(det)));
    }
  return worst;
}

}  // namespace planarvo::track
