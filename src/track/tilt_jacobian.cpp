#include "track/tilt_jacobian.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "track/warp_model.h"

namespace planarvo::track {
namespace {

WarpReduceOptions plain(WarpReduceOptions k) {
  k.stats = k.debug_output = false;
  k.select_block = 0;
  return k;
}

}  // namespace

TiltJacobian::TiltJacobian(ocl::Runtime& runtime, const WarpReduceOptions& kernel)
    : pass_(runtime, kMotionParams + kOrientationParams, plain(kernel)) {}

Eigen::Matrix<double, 3, 2> TiltJacobian::operator()(const Pyramid& reference, const Pyramid& live,
                                                     const Eigen::Matrix3d& K, const Extrinsics& e, const SE2& motion,
                                                     double log_gain, double bias, double huber_k,
                                                     bool with_brightness) {
  const int level = std::min(1, std::min(reference.num_levels(), live.num_levels()) - 1);
  if (level < 0) return Eigen::Matrix<double, 3, 2>::Zero();
  const PyramidLevel& r = reference.levels[static_cast<size_t>(level)];
  const PyramidLevel& l = live.levels[static_cast<size_t>(level)];
  const MotionHomography mh = motion_homography(level_camera_matrix(K, level), e, motion, true);
  WarpInputs in;
  in.H = mh.H;
  in.nparam = mh.nparam;
  for (int i = 0; i < mh.nparam; ++i) in.G[static_cast<size_t>(i)] = mh.G[static_cast<size_t>(i)];
  in.gain = std::exp(log_gain);
  in.bias = bias;
  in.huber_k = huber_k > 0.0 ? huber_k : 1e30;
  ReduceSums s;
  pass_.run(r.data, r.width, r.height, l.data, l.width, l.height, in, &s);

  // Local parameters: the motion, then the brightness (a, b) when estimated; the tilt y at 3, 4.
  std::vector<int> local = {0, 1, 2};
  if (with_brightness) local.insert(local.end(), {5, 6});
  const int n = static_cast<int>(local.size());
  Eigen::MatrixXd All(n, n), Aly(n, 2);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) All(i, j) = s.JtWJ(local[static_cast<size_t>(i)], local[static_cast<size_t>(j)]);
    for (int j = 0; j < 2; ++j) Aly(i, j) = s.JtWJ(local[static_cast<size_t>(i)], 3 + j);
  }
  const Eigen::MatrixXd dy = -All.ldlt().solve(Aly);

  // Per angle, the rotation it makes, w = log(R_vc(angle + h) R_vc^T) / h in the robot frame: its
  // horizontal part through dy; its vertical part turns the ground frame the pose is expressed
  // in, so the pose P becomes Rz(w_z) P Rz(-w_z).
  Eigen::Matrix<double, 3, 2> out;
  const double h = 1e-6;
  // Rz(a) P Rz(-a) = P exp(a (Ad_{P^-1} - 1) e_theta).
  const Eigen::Vector3d turn = motion.inverse().adjoint().col(2) - Eigen::Vector3d::UnitZ();
  for (int c = 0; c < 2; ++c) {
    Extrinsics moved = e;
    (c == 0 ? moved.roll : moved.pitch) += h;
    const Eigen::AngleAxisd w(moved.R_vc() * e.R_vc().transpose());
    const Eigen::Vector3d omega = w.angle() * w.axis() / h;
    out.col(c) = dy.topRows(3) * omega.head<2>() + turn * omega.z();
  }
  return out.allFinite() ? out : Eigen::Matrix<double, 3, 2>::Zero();
}

}  // namespace planarvo::track
