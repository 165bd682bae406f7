// Sparse Levenberg–Marquardt on a FactorGraph: minimises Σ ρ(eᵀΩe) (χ² units: no ½).
//
// Each iteration solves (H + λD)δ = −g, by a numeric CHOLMOD factorisation (symbolic analysis
// once per graph structure) or, while it stays a good preconditioner, by CG on the last factor
// (see reuse_factorization); the gain ratio ρ = actual / predicted decrease decides:
//   accepted (ρ > min_relative_decrease): λ *= max(1/10, 1 − (2ρ − 1)³), ν = 2   (Nielsen)
//   rejected, or the factorisation failed: λ *= ν, ν *= 2
// A factorisation that fails (H + λD not positive definite, e.g. a free gauge with λ = 0) is a
// rejected step, never an abort.
//
// Damping: Marquardt's D = diag(H) (clamped) by default, invariant to the units of each
// parameter (metres, radians, a height scale). Measured (test/bench/bench_posegraph): from the
// files' initial values, Levenberg's D = I with g2o's settings (λ₀ = 1e-5·max diag(H), additive
// steps, 3× decrease) stops on city10000 at χ² 1484.7 (2.9× the optimum 511.985; 2598 with the
// other defaults here) where Marquardt's reaches the optimum from either start. The start
// λ₀ = 1e-8 (Ceres: 1e-4) and the faster decrease (at most 10×, Nielsen and Ceres: 3×) were
// measured too: λ·diag(H) was what held back steps that the model predicted perfectly (ρ ≈ 1)
// in the weakly constrained directions of long chains; manhattanOlson3500 26 → 6 iterations,
// ringCity 34 → 8, ring 20 → 6, to the same optima. A bad step costs a rejection and λ grows
// geometrically from there.
#pragma once
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "graph/solver/factor_graph.h"
#include "graph/solver/normal_equations.h"

namespace planarvo::graph {

struct IterationSummary;

struct SolverOptions {
  // Iterations (factorisations, accepted or not) before giving up. Ceres' default is 50.
  int max_iterations = 100;
  // Stop when a step changes the cost by less than this fraction of it (Ceres' default).
  double function_tolerance = 1e-6;
  // Stop when the largest gradient component max|J̃ᵀr̃| falls below this (Ceres' default).
  double gradient_tolerance = 1e-10;
  // Stop when |δ| ≤ tol·(|x| + tol), x the free parameters (Ceres' default).
  double parameter_tolerance = 1e-8;
  // Damping: see the header comment. initial_lambda is relative to D; for Levenberg damping it
  // is g2o's τ, relative to max diag(H) (g2o uses 1e-5). Ceres' initial trust-region radius
  // 1e4 corresponds to 1e-4.
  Damping damping = Damping::Marquardt;
  double initial_lambda = 1e-8;
  // The largest decrease of λ after one accepted step: Nielsen's rule is
  // λ *= max(1 / lambda_max_decrease, 1 − (2ρ − 1)³), with 3 in Nielsen, g2o and Ceres.
  double lambda_max_decrease = 10.0;
  double min_lambda = 1e-16;  // λ never drops below (Ceres' max trust-region radius 1e16)
  double max_lambda = 1e32;   // beyond this the solver gives up (TerminationType::DampingLimit)
  // A step is accepted when ρ exceeds this (Ceres' default).
  double min_relative_decrease = 1e-3;
  // Reuse of the Cholesky factor: while the last factorisation stays a good preconditioner,
  // a step is computed by conjugate gradients on the new H + λD preconditioned with it (sparse
  // products and triangular solves), until ‖residual‖ ≤ reuse_cg_tolerance·‖g‖. CG may spend
  // at most reuse_cg_budget of a factorisation's estimated work (NormalEquations::factor_cost)
  // and reuse_max_cg_iterations; past
  // that H is refactorised, and reuse waits 1, 2, 4, ... iterations before the next attempt.
  // Where the budget allows fewer than 2 CG iterations (small or very sparse factors) reuse is
  // off. Every step still passes the gain-ratio test on the true cost; the choice depends on
  // the factor's size only, not on timing, so runs are reproducible. false: one factorisation
  // per iteration.
  bool reuse_factorization = true;
  double reuse_cg_budget = 0.5;
  int reuse_max_cg_iterations = 10;
  double reuse_cg_tolerance = 1e-3;
  // Seconds before giving up; infinity for no limit.
  double max_time_s = std::numeric_limits<double>::infinity();
  LinearSolverOptions linear;
  // Called after every iteration; returning false stops the solver (TerminationType::UserStop).
  std::function<bool(const IterationSummary&)> callback;
};

enum class TerminationType {
  FunctionTolerance,   // converged: relative cost change below function_tolerance
  GradientTolerance,   // converged: gradient max-norm below gradient_tolerance
  ParameterTolerance,  // converged: step below parameter_tolerance
  MaxIterations,       // not converged: iteration cap
  MaxTime,             // not converged: time cap
  DampingLimit,        // not converged: λ exceeded max_lambda (no step lowers the cost)
  NothingToOptimize,   // every variable is fixed
  NumericalFailure,    // the cost is not finite at the initial values
  UserStop,            // the callback asked to stop
};

std::string to_string(TerminationType type);

struct IterationSummary {
  int iteration = 0;             // 0: the initial point
  double cost = 0.0;             // cost after this iteration (the accepted point)
  double cost_change = 0.0;      // decrease the trial step achieved (negative: increase)
  double gradient_max_norm = 0.0;  // at the accepted point
  double step_norm = 0.0;        // |δ| of the trial step
  double lambda = 0.0;           // damping the trial step was computed with
  double relative_decrease = 0.0;  // ρ = actual / predicted decrease
  bool factorization_ok = true;
  bool refactorized = false;     // a numeric factorisation (else a reused factor, or none)
  int cg_iterations = 0;         // CG iterations when the factor was reused
  bool step_accepted = false;
  double iteration_time_s = 0.0;
  double cumulative_time_s = 0.0;
};

struct SolverSummary {
  TerminationType termination = TerminationType::NothingToOptimize;
  std::string message;  // why it stopped, with the numbers
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int num_iterations = 0;  // LM iterations (not counting the initial evaluation)
  int num_accepted = 0;
  int num_rejected = 0;             // steps that did not lower the cost enough
  int num_failed_factorizations = 0;  // H + λD not positive definite
  int num_factorizations = 0;         // numeric factorisations (the rest reused one)
  std::vector<IterationSummary> iterations;  // [0] is the initial point
  PhaseTimes times;
  double total_time_s = 0.0;
  int num_parameters = 0;  // free parameters (columns)
  int num_factors = 0;
  double factor_nonzeros = 0.0;  // nnz(L)
  double factor_flops = 0.0;     // flops of one numeric factorisation
  std::string linear_solver;      // ordering and factorisation CHOLMOD used

  bool converged() const;
  // One line: termination, costs, iterations, time.
  std::string brief_report() const;
  // The iteration table, phase times and the termination.
  std::string full_report() const;
};

class Solver {
 public:
  explicit Solver(SolverOptions options = {});
  ~Solver();
  Solver(Solver&&) noexcept;
  Solver& operator=(Solver&&) noexcept;

  // Optimises the graph's values in place. The symbolic analysis is kept and reused by the next
  // call while the graph's structure and the linear options stay the same.
  SolverSummary solve(FactorGraph& graph);

  const SolverOptions& options() const { return options_; }
  SolverOptions& options() { return options_; }

 private:
  SolverOptions options_;
  std::unique_ptr<NormalEquations> system_;
};

// One-shot convenience.
SolverSummary solve(FactorGraph& graph, const SolverOptions& options = {});

}  // namespace planarvo::graph
