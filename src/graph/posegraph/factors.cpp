#include "graph/posegraph/factors.h"

#include <cmath>

#include "core/error.h"

namespace planarvo::graph {

RelativePoseFactor::RelativePoseFactor(VariableId from, VariableId to, const SE2& measurement,
                                       const Eigen::Matrix3d& information)
    : Factor({from, to}, {VariableType::pose2(), VariableType::pose2()}, information),
      measurement_(measurement),
      cz_(std::cos(measurement.theta)),
      sz_(std::sin(measurement.theta)) {}

void RelativePoseFactor::evaluate(const double* const* values, double* e,
                                  double* const* jacobians) const {
  const double* a = values[0];
  const double* b = values[1];
  const double ci = std::cos(a[2]), si = std::sin(a[2]);
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  // X_i⁻¹·X_j: translation R_iᵀ(t_j − t_i); then Z⁻¹·(…): R_Zᵀ(t_A − t_Z).
  const double ax = ci * dx + si * dy, ay = -si * dx + ci * dy;
  const double ux = ax - measurement_.x, uy = ay - measurement_.y;
  e[0] = cz_ * ux + sz_ * uy;
  e[1] = -sz_ * ux + cz_ * uy;
  e[2] = wrap_angle(b[2] - a[2] - measurement_.theta);
  if (!jacobians) return;
  // de_t/dt_j = R_Zᵀ R_iᵀ = R(−(θ_i + θ_Z)); de_t/dθ_i = R_Zᵀ · (dR_iᵀ/dθ)(t_j − t_i).
  const double c = ci * cz_ - si * sz_, s = si * cz_ + ci * sz_;
  if (double* J = jacobians[0]) {
    J[0] = -c, J[1] = s, J[2] = 0.0;
    J[3] = -s, J[4] = -c, J[5] = 0.0;
    J[6] = cz_ * ay - sz_ * ax, J[7] = -sz_ * ay - cz_ * ax, J[8] = -1.0;
  }
  if (double* J = jacobians[1]) {
    J[0] = c, J[1] = -s, J[2] = 0.0;
    J[3] = s, J[4] = c, J[5] = 0.0;
    J[6] = 0.0, J[7] = 0.0, J[8] = 1.0;
  }
}

PosePriorFactor::PosePriorFactor(VariableId pose, const SE2& prior,
                                 const Eigen::Matrix3d& information)
    : Factor({pose}, {VariableType::pose2()}, information),
      prior_(prior),
      cz_(std::cos(prior.theta)),
      sz_(std::sin(prior.theta)) {}

void PosePriorFactor::evaluate(const double* const* values, double* e,
                               double* const* jacobians) const {
  const double* x = values[0];
  const double ux = x[0] - prior_.x, uy = x[1] - prior_.y;
  e[0] = cz_ * ux + sz_ * uy;
  e[1] = -sz_ * ux + cz_ * uy;
  e[2] = wrap_angle(x[2] - prior_.theta);
  if (jacobians && jacobians[0]) {
    double* J = jacobians[0];
    J[0] = cz_, J[1] = -sz_, J[2] = 0.0;
    J[3] = sz_, J[4] = cz_, J[5] = 0.0;
    J[6] = 0.0, J[7] = 0.0, J[8] = 1.0;
  }
}

VectorPriorFactor::VectorPriorFactor(VariableId variable, const Eigen::VectorXd& prior,
                                     const Eigen::MatrixXd& information)
    : Factor({variable}, {VariableType::vector(static_cast<int>(prior.size()))}, information),
      prior_(prior) {
  if (information.rows() != prior.size())
    throw_invalid_argument("VectorPriorFactor: the information must be n × n for a prior of n");
}

void VectorPriorFactor::evaluate(const double* const* values, double* e,
                                 double* const* jacobians) const {
  const auto n = prior_.size();
  Eigen::Map<Eigen::VectorXd>(e, n) = Eigen::Map<const Eigen::VectorXd>(values[0], n) - prior_;
  if (jacobians && jacobians[0]) Eigen::Map<Eigen::MatrixXd>(jacobians[0], n, n).setIdentity();
}

}  // namespace planarvo::graph
