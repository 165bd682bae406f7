// Uncertainty and observability of chosen variables at the graph's current values (normally
// the optimum), from the Gauss–Newton information H = J̃ᵀJ̃ (robust weights included). Always in
// stored coordinates (x, y, θ for poses; components for vectors), whatever retraction the solver
// used; fixed parameters have zero rows and columns.
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

#include "graph/solver/factor_graph.h"
#include "graph/solver/normal_equations.h"

namespace planarvo::graph {

// The marginal covariance of the chosen variables: their blocks of H⁻¹, from one sparse
// factorisation of H and solves for the needed columns of the inverse (the chosen variables'
// identity columns). Throws Error(Failed) when H is not positive definite (some direction is
// unobservable: analyse_observability names it).
class MarginalCovariance {
 public:
  MarginalCovariance(const FactorGraph& graph, std::vector<VariableId> variables,
                     const LinearSolverOptions& options = {});
  // Cov(a, b): dim_a × dim_b, a and b among the chosen variables.
  Eigen::MatrixXd block(VariableId a, VariableId b) const;
  Eigen::MatrixXd covariance(VariableId v) const { return block(v, v); }
  // The joint covariance of all chosen variables, stacked in the order given.
  Eigen::MatrixXd joint() const;

 private:
  int index_of(VariableId v) const;
  std::vector<VariableId> variables_;
  std::vector<int> dims_;
  std::vector<int> start_;  // row of each chosen variable in joint_
  Eigen::MatrixXd joint_;
};

// One-variable shorthand.
Eigen::MatrixXd marginal_covariance(const FactorGraph& graph, VariableId v,
                                    const LinearSolverOptions& options = {});

// Observability of a block of variables (e.g. the calibration node z): the marginal information
// of the block after the other variables are eliminated (the Schur complement
// S = H_bb − H_bo H_oo⁻¹ H_ob), its rank, conditioning and null space. S is also defined when
// the block itself is unobservable, which H⁻¹ is not; it needs only the other variables to be
// determined once the block is known (otherwise Error(Failed), e.g. a free gauge).
//
// Rank and condition are taken on the correlation-scaled S (D^-½ S D^-½, D = diag S), so that
// metres, radians and a height scale compare. Before scaling, a parameter with roundoff-sized
// information is declared unobservable outright: S_ii ≤ relative_tolerance · H_bb,ii (the
// elimination cancelled it, as for a gauge) or S_ii ≤ relative_tolerance · max_j S_jj (SI units).
// relative_tolerance thus bounds the weakest information called observable.
struct ObservabilityReport {
  std::vector<std::string> parameter_names;  // "z.x", ... the free parameters of the block
  Eigen::MatrixXd information;               // S, over those parameters
  Eigen::VectorXd eigenvalues;               // of the scaled S, ascending
  Eigen::MatrixXd eigenvectors;              // of the scaled S, columns
  int rank = 0;
  double condition_number = 0.0;             // of the scaled S; infinite when rank-deficient
  double relative_tolerance = 0.0;           // eigenvalue / largest below this: null space
  // Unobservable directions in parameter units (unit vectors), and the parameters taking part
  // in them (a component of at least 0.1 in the scaled direction).
  std::vector<Eigen::VectorXd> null_space;
  std::vector<std::string> unobservable;

  bool observable() const { return rank == static_cast<int>(parameter_names.size()); }
  // "rank 3 of 4, condition 1.2e+03; unobservable: z.y" and the null-space directions.
  std::string describe() const;
};

ObservabilityReport analyse_observability(const FactorGraph& graph,
                                          const std::vector<VariableId>& block,
                                          double relative_tolerance = 1e-9,
                                          const LinearSolverOptions& options = {});

}  // namespace planarvo::graph
