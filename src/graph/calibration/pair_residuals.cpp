#include "graph/calibration/pair_residuals.h"

#include <cmath>

#include <Eigen/Dense>

#include "graph/calibration/factors.h"

namespace planarvo::graph {

PairResidual pair_residual(const SE2& odometry, const SE2& sensor, const Eigen::Matrix3d& odometry_cov,
                           const Eigen::Matrix3d& sensor_cov, const Eigen::Vector4d& z) {
  const double x = z[CalibrationIndex::kX], y = z[CalibrationIndex::kY], h = z[CalibrationIndex::kHeight];
  const double yaw = z[CalibrationIndex::kYaw];
  const SE2 M = sensor_to_robot_motion(sensor, z.data());
  PairResidual r;
  r.d = Eigen::Vector3d(odometry.x - M.x, odometry.y - M.y, std::remainder(odometry.theta - M.theta, 2.0 * M_PI));
  // G = diag(1/h, 1/h, 1) Ad(T)⁻¹ as the sensor factor applies it (factors.h).
  const double cg = std::cos(yaw), sg = std::sin(yaw);
  Eigen::Matrix2d Rt;
  Rt << cg, sg, -sg, cg;
  Eigen::Matrix2d J;
  J << 0.0, -1.0, 1.0, 0.0;
  Eigen::Matrix3d G = Eigen::Matrix3d::Identity();
  G.topLeftCorner<2, 2>() = Rt / h;
  G.topRightCorner<2, 1>() = J * Rt * Eigen::Vector2d(x, y) / h;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R.topLeftCorner<2, 2>() << std::cos(M.theta), -std::sin(M.theta), std::sin(M.theta), std::cos(M.theta);
  const Eigen::Matrix3d K = R * G.inverse() * R.transpose();
  r.covariance = odometry_cov + K * sensor_cov * K.transpose();
  r.chi2 = r.d.dot(r.covariance.ldlt().solve(r.d));
  return r;
}

}  // namespace planarvo::graph
