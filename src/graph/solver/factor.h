// The factor interface: a measurement's error e(x) of some variables, its analytic Jacobians and
// its information matrix Ω. The solver minimises Σ ρ(eᵀΩe) over all factors.
//
// Jacobians are taken with respect to the variables' stored coordinates: (x, y, θ) for a pose,
// the components for a vector. The solver maps them to its retraction itself (see
// solver.h, PoseRetraction), so a factor never needs to know how the solver steps.
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

namespace planarvo::graph {

// Index of a variable in its FactorGraph.
using VariableId = int;

enum class VariableKind {
  Pose2,   // SE(2) pose (x, y, θ); θ is kept wrapped to (-π, π]
  Vector,  // a small Euclidean vector, e.g. the calibration node z = (x, y, height, yaw)
};

struct VariableType {
  VariableKind kind = VariableKind::Vector;
  int dim = 0;
  static VariableType pose2() { return {VariableKind::Pose2, 3}; }
  static VariableType vector(int n) { return {VariableKind::Vector, n}; }
  bool operator==(const VariableType& o) const { return kind == o.kind && dim == o.dim; }
};

std::string to_string(const VariableType& type);

class Factor {
 public:
  // `types[k]` is what variables[k] must be; FactorGraph::add_factor checks it. `information`
  // must be symmetric positive definite (residual_dim × residual_dim).
  Factor(std::vector<VariableId> variables, std::vector<VariableType> types,
         const Eigen::MatrixXd& information);
  virtual ~Factor() = default;
  Factor(const Factor&) = delete;
  Factor& operator=(const Factor&) = delete;

  const std::vector<VariableId>& variables() const { return variables_; }
  const std::vector<VariableType>& types() const { return types_; }
  int residual_dim() const { return residual_dim_; }

  // The error e (residual_dim values) at the variables' values (values[k] points at variable k's
  // stored coordinates) and, for every k with jacobians[k] != nullptr, de/dvalues[k] as a
  // residual_dim × dim_k column-major matrix. Must not allocate: the solver calls it per
  // iteration for every factor.
  virtual void evaluate(const double* const* values, double* error,
                        double* const* jacobians) const = 0;

  // The square root L of the information (Ω = LᵀL, L upper triangular, column-major) at the
  // given values. Constant unless a factor overrides both functions below; a state-dependent
  // information is treated as a weight frozen at each evaluation (its derivative is not part of
  // the Jacobian, as in the paper's eq. 27 projection of Ω).
  virtual bool information_depends_on_state() const { return false; }
  virtual void sqrt_information_at(const double* const* values, double* sqrt_information) const;

  // The constant information given at construction, and its square root.
  const Eigen::MatrixXd& information() const { return information_; }
  const Eigen::MatrixXd& sqrt_information() const { return sqrt_information_; }

 protected:
  void set_information(const Eigen::MatrixXd& information);

 private:
  std::vector<VariableId> variables_;
  std::vector<VariableType> types_;
  int residual_dim_ = 0;
  Eigen::MatrixXd information_;
  Eigen::MatrixXd sqrt_information_;
};

}  // namespace planarvo::graph
