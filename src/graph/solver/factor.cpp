#include "graph/solver/factor.h"

#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>

#include "core/error.h"

namespace planarvo::graph {

std::string to_string(const VariableType& type) {
  std::ostringstream s;
  if (type.kind == VariableKind::Pose2)
    s << "SE(2) pose";
  else
    s << "vector of " << type.dim;
  return s.str();
}

Factor::Factor(std::vector<VariableId> variables, std::vector<VariableType> types,
               const Eigen::MatrixXd& information)
    : variables_(std::move(variables)), types_(std::move(types)) {
  if (variables_.empty() || variables_.size() != types_.size())
    throw_invalid_argument("Factor: needs at least one variable and one type per variable");
  set_information(information);
}

void Factor::set_information(const Eigen::MatrixXd& information) {
  const auto n = information.rows();
  if (n == 0 || information.cols() != n)
    throw_invalid_argument("Factor: the information matrix must be square and non-empty");
  if (!information.allFinite() || (information - information.transpose()).cwiseAbs().maxCoeff() >
                                      1e-9 * information.cwiseAbs().maxCoeff())
    throw_invalid_argument("Factor: the information matrix must be finite and symmetric");
  Eigen::LLT<Eigen::MatrixXd> llt(information);
  if (llt.info() != Eigen::Success || !(llt.matrixL().toDenseMatrix().diagonal().minCoeff() > 0.0))
    throw_invalid_argument("Factor: the information matrix must be positive definite");
  information_ = information;
  sqrt_information_ = llt.matrixU();
  residual_dim_ = static_cast<int>(n);
}

void Factor::sqrt_information_at(const double* const*, double* sqrt_information) const {
  Eigen::Map<Eigen::MatrixXd>(sqrt_information, residual_dim_, residual_dim_) = sqrt_information_;
}

}  // namespace planarvo::graph
