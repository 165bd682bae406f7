#include "graph/calibration/odometry_noise.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Dense>

namespace planarvo::graph {

namespace {

// min |M x - b| over x >= 0, for three columns: a negative coefficient's column is dropped and the
// rest solved again.
Eigen::Vector3d nonnegative_least_squares(const Eigen::MatrixXd& M, const Eigen::VectorXd& b) {
  std::array<bool, 3> active = {true, true, true};
  for (int round = 0; round < 3; ++round) {
    std::vector<int> cols;
    for (int k = 0; k < 3; ++k)
      if (active[static_cast<size_t>(k)]) cols.push_back(k);
    if (cols.empty()) break;
    Eigen::MatrixXd S(M.rows(), static_cast<Eigen::Index>(cols.size()));
    for (size_t k = 0; k < cols.size(); ++k) S.col(static_cast<Eigen::Index>(k)) = M.col(cols[k]);
    const Eigen::VectorXd x = S.colPivHouseholderQr().solve(b);
    Eigen::Vector3d coef = Eigen::Vector3d::Zero();
    bool negative = false;
    for (size_t k = 0; k < cols.size(); ++k) {
      coef(cols[k]) = x(static_cast<Eigen::Index>(k));
      if (x(static_cast<Eigen::Index>(k)) < 0.0) {
        active[static_cast<size_t>(cols[k])] = false;
        negative = true;
      }
    }
    if (!negative) return coef;
  }
  return Eigen::Vector3d::Zero();
}

}  // namespace

Eigen::Matrix3d OdometryNoiseModel::covariance(const SE2& m) const {
  const double t2 = m.x * m.x + m.y * m.y, r2 = m.theta * m.theta;
  Eigen::Vector3d v = constant + per_translation * t2 + per_rotation * r2;
  v(0) = std::max(v(0), floor_translation * floor_translation);
  v(1) = std::max(v(1), floor_translation * floor_translation);
  v(2) = std::max(v(2), floor_rotation * floor_rotation);
  return v.asDiagonal();
}

OdometryNoiseModel fit_odometry_noise(const std::vector<SE2>& odometry, const std::vector<Eigen::Vector3d>& residual) {
  OdometryNoiseModel model;
  const size_t n = std::min(odometry.size(), residual.size());
  if (n < 10) return model;
  Eigen::MatrixXd A(static_cast<Eigen::Index>(n), 3);
  for (size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    A(r, 0) = 1.0;
    A(r, 1) = odometry[i].x * odometry[i].x + odometry[i].y * odometry[i].y;
    A(r, 2) = odometry[i].theta * odometry[i].theta;
  }
  // The columns differ by orders of magnitude (1, m^2, rad^2): scale them for the solve.
  const Eigen::Vector3d scale = A.colwise().norm().transpose().cwiseMax(1e-300);
  const Eigen::MatrixXd As = A * scale.cwiseInverse().asDiagonal();
  for (int c = 0; c < 3; ++c) {
    Eigen::VectorXd b(static_cast<Eigen::Index>(n));
    for (size_t i = 0; i < n; ++i) b(static_cast<Eigen::Index>(i)) = residual[i](c) * residual[i](c);
    // A squared residual's variance is 2 sigma^4: weighted least squares with weights 1 / sigma^4
    // of the previous fit (iteratively; the first unweighted), so that small-variance intervals
    // (turning in place, standing) are fitted as well as large ones.
    Eigen::VectorXd w = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(n));
    Eigen::Vector3d coef = Eigen::Vector3d::Zero();
    const double tiny = 1e-30 + 1e-6 * b.mean();
    for (int iteration = 0; iteration < 6; ++iteration) {
      coef = nonnegative_least_squares(w.asDiagonal() * As, w.asDiagonal() * b);
      const Eigen::VectorXd predicted = As * coef;
      for (Eigen::Index i = 0; i < w.size(); ++i) w(i) = 1.0 / std::max(predicted(i), tiny);
      w /= w.maxCoeff();
    }
    coef = coef.cwiseQuotient(scale).cwiseMax(0.0);
    model.constant(c) = coef(0);
    model.per_translation(c) = coef(1);
    model.per_rotation(c) = coef(2);
  }
  return model;
}

}  // namespace planarvo::graph
