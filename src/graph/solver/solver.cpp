#include "graph/solver/solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace planarvo::graph {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

bool same_linear_options(const LinearSolverOptions& a, const LinearSolverOptions& b) {
  return a.ordering == b.ordering && a.factorization == b.factorization &&
         a.supernodal_switch == b.supernodal_switch &&
         a.retraction == b.retraction && a.min_diagonal == b.min_diagonal &&
         a.max_diagonal == b.max_diagonal;
}

// A number for messages, with `digits` significant digits.
std::string num(double v, int digits = 3) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

std::string to_string(TerminationType type) {
  switch (type) {
    case TerminationType::FunctionTolerance: return "FunctionTolerance";
    case TerminationType::GradientTolerance: return "GradientTolerance";
    case TerminationType::ParameterTolerance: return "ParameterTolerance";
    case TerminationType::MaxIterations: return "MaxIterations";
    case TerminationType::MaxTime: return "MaxTime";
    case TerminationType::DampingLimit: return "DampingLimit";
    case TerminationType::NothingToOptimize: return "NothingToOptimize";
    case TerminationType::NumericalFailure: return "NumericalFailure";
    case TerminationType::UserStop: return "UserStop";
  }
  return "Unknown";
}

bool SolverSummary::converged() const {
  return termination == TerminationType::FunctionTolerance ||
         termination == TerminationType::GradientTolerance ||
         termination == TerminationType::ParameterTolerance ||
         termination == TerminationType::NothingToOptimize;
}

std::string SolverSummary::brief_report() const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%s: cost %.6g -> %.6g in %d iterations (%d accepted), %.1f ms", 
                to_string(termination).c_str(), initial_cost, final_cost, num_iterations,
                num_accepted, total_time_s * 1e3);
  return buf;
}

std::string SolverSummary::full_report() const {
  std::ostringstream s;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "Levenberg-Marquardt: %d parameters, %d factors, CHOLMOD %s, nnz(L) %.0f, "
                "%.3g flops per factorisation\n",
                num_parameters, num_factors, linear_solver.c_str(), factor_nonzeros, factor_flops);
  s << buf;
  s << "iter        cost   cost_change  |gradient|      |step|      lambda       rho  "
       "step  linear      ms  total_ms\n";
  for (const IterationSummary& it : iterations) {
    const char* what = it.iteration == 0 ? "    "
                       : !it.factorization_ok ? "npd "
                       : it.step_accepted ? "ok  "
                                           : "rej ";
    char linear[16] = "";
    if (it.iteration > 0 && it.refactorized) std::snprintf(linear, sizeof linear, "chol");
    if (it.iteration > 0 && !it.refactorized) std::snprintf(linear, sizeof linear, "cg %d", it.cg_iterations);
    std::snprintf(buf, sizeof buf,
                  "%4d %11.6g %13.6g %11.4g %11.4g %11.4g %9.3g  %s  %-6s %7.2f %9.2f\n",
                  it.iteration, it.cost, it.cost_change, it.gradient_max_norm, it.step_norm,
                  it.lambda, it.relative_decrease, what, linear, it.iteration_time_s * 1e3,
                  it.cumulative_time_s * 1e3);
    s << buf;
  }
  std::snprintf(buf, sizeof buf,
                "iterations %d: %d accepted, %d rejected, %d failed factorisations; "
                "%d numeric factorisations\n",
                num_iterations, num_accepted, num_rejected, num_failed_factorizations,
                num_factorizations);
  s << buf;
  std::snprintf(buf, sizeof buf,
                "time (ms): analyze %.2f, linearize %.2f, factorize %.2f, "
                "solve %.2f, evaluate %.2f, total %.2f\n",
                times.analyze * 1e3, times.linearize * 1e3,
                times.factorize * 1e3, times.solve * 1e3, times.evaluate * 1e3,
                total_time_s * 1e3);
  s << buf;
  s << "cost " << num(initial_cost, 10) << " -> " << num(final_cost, 10) << "\n";
  s << "termination: " << to_string(termination) << ": " << message << "\n";
  return s.str();
}

Solver::Solver(SolverOptions options) : options_(std::move(options)) {}
Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

SolverSummary Solver::solve(FactorGraph& graph) {
  const auto t_start = Clock::now();
  const SolverOptions& o = options_;
  SolverSummary summary;
  summary.num_factors = graph.num_factors();

  if (!system_ || !system_->matches(graph) || !same_linear_options(system_->options(), o.linear)) {
    system_.reset();
    system_ = std::make_unique<NormalEquations>(graph, o.linear);
    summary.times.analyze = system_->analyze_seconds();
  }
  NormalEquations& sys = *system_;
  summary.num_parameters = sys.num_columns();
  summary.factor_nonzeros = sys.factor_nonzeros();
  summary.factor_flops = sys.factor_flops();
  summary.linear_solver = sys.ordering_used();

  summary.iterations.reserve(static_cast<size_t>(std::max(o.max_iterations, 0)) + 1);
  std::vector<double> x = graph.values();
  std::vector<double> trial = x;
  PhaseTimes& times = summary.times;

  auto finish = [&](TerminationType type, std::string message) {
    summary.termination = type;
    summary.message = std::move(message);
    summary.total_time_s = seconds_since(t_start);
    graph.set_values(x);
    return summary;
  };

  if (sys.num_columns() == 0) {
    summary.initial_cost = summary.final_cost = sys.evaluate_cost(x.data(), &times);
    IterationSummary it0;
    it0.cost = summary.initial_cost;
    summary.iterations.push_back(it0);
    return finish(TerminationType::NothingToOptimize, "every variable is fixed");
  }

  double cost = sys.linearize(x.data(), &times);
  summary.initial_cost = summary.final_cost = cost;
  double gmax = sys.gradient().cwiseAbs().maxCoeff();
  {
    IterationSummary it0;
    it0.cost = cost;
    it0.gradient_max_norm = gmax;
    it0.iteration_time_s = it0.cumulative_time_s = seconds_since(t_start);
    summary.iterations.push_back(it0);
  }
  if (!std::isfinite(cost) || !std::isfinite(gmax))
    return finish(TerminationType::NumericalFailure,
                  "the cost or its gradient is not finite at the initial values");

  // λ in units of D: Levenberg's D = I needs the scale of H.
  const double lambda_scale =
      o.damping == Damping::Levenberg ? std::max(sys.hessian_diagonal().maxCoeff(), 1e-300) : 1.0;
  double lambda = std::max(o.initial_lambda * lambda_scale, o.min_lambda);
  double nu = 2.0;
  // Factor reuse: CG iterations worth a fraction of a factorisation, and the back-off.
  const int cg_budget =
      o.reuse_factorization
          ? static_cast<int>(std::min<double>(
                o.reuse_max_cg_iterations,
                std::floor(o.reuse_cg_budget * sys.factor_cost() /
                           std::max(sys.cg_iteration_cost(), 1.0))))
          : 0;
  int reuse_skip = 0, reuse_backoff = 1;
  Eigen::VectorXd delta;

  for (int iter = 1;; ++iter) {
    if (gmax <= o.gradient_tolerance)
      return finish(TerminationType::GradientTolerance,
                    "gradient max-norm " + num(gmax) + " <= " + num(o.gradient_tolerance));
    if (iter > o.max_iterations)
      return finish(TerminationType::MaxIterations,
                    "reached " + std::to_string(o.max_iterations) + " iterations");
    if (seconds_since(t_start) > o.max_time_s)
      return finish(TerminationType::MaxTime, "exceeded " + num(o.max_time_s) + " s");

    const auto t_iter = Clock::now();
    IterationSummary it;
    it.iteration = iter;
    it.lambda = lambda;
    summary.num_iterations = iter;

    bool ok = false;
    if (cg_budget >= 2 && sys.has_factor() && reuse_skip-- <= 0) {
      it.cg_iterations = sys.solve_step_reusing_factor(lambda, o.damping, delta, cg_budget,
                                                       o.reuse_cg_tolerance, &times);
      ok = it.cg_iterations > 0;
      if (ok) {
        reuse_backoff = 1;
      } else {
        // The factor no longer preconditions well: replace it now, and back off.
        reuse_skip = reuse_backoff;
        reuse_backoff *= 2;
      }
    }
    if (!ok) {
      it.cg_iterations = 0;
      it.refactorized = true;
      ++summary.num_factorizations;
      ok = sys.factorize(lambda, o.damping, &times) && sys.solve_step(delta, &times);
      it.factorization_ok = ok;
    }
    std::string converged_message;  // set when the function tolerance is met
    if (ok) {
      it.step_norm = delta.norm();
      const double x_norm = sys.free_values_norm(x.data());
      if (it.step_norm <= o.parameter_tolerance * (x_norm + o.parameter_tolerance)) {
        // A negligible step: converged at the current point, nothing to try or record.
        summary.num_iterations = iter - 1;
        return finish(TerminationType::ParameterTolerance,
                      "step " + num(it.step_norm) +
                          " <= parameter_tolerance * (|x| + tol) with |x| = " + num(x_norm));
      }
      sys.retract(x.data(), delta, trial.data());
      const double new_cost = sys.evaluate_cost(trial.data(), &times);
      const double predicted = it.refactorized ? sys.predicted_decrease_of_solution(delta)
                                               : sys.predicted_decrease(delta);
      it.cost_change = cost - new_cost;
      it.relative_decrease = predicted > 0.0 ? it.cost_change / predicted : -1.0;
      it.step_accepted = std::isfinite(new_cost) && predicted > 0.0 &&
                         it.relative_decrease > o.min_relative_decrease;
      if (std::isfinite(new_cost) && std::abs(it.cost_change) <= o.function_tolerance * cost)
        converged_message = "relative cost change " +
                            num(std::abs(it.cost_change) / std::max(cost, 1e-300)) + " <= " +
                            num(o.function_tolerance);
    }

    if (it.step_accepted) {
      ++summary.num_accepted;
      x.swap(trial);
      cost = sys.linearize(x.data(), &times);
      gmax = sys.gradient().cwiseAbs().maxCoeff();
      const double r = 2.0 * it.relative_decrease - 1.0;
      lambda = std::max(lambda * std::max(1.0 / o.lambda_max_decrease, 1.0 - r * r * r),
                        o.min_lambda);
      nu = 2.0;
    } else {
      if (ok)
        ++summary.num_rejected;
      else
        ++summary.num_failed_factorizations;
      // From λ = 0 (pure Gauss–Newton allowed by the options) doubling stays at 0: restart
      // from a small damping instead.
      lambda = lambda > 0.0 ? lambda * nu : 1e-8 * lambda_scale;
      nu *= 2.0;
    }
    it.cost = cost;
    it.gradient_max_norm = gmax;
    it.iteration_time_s = seconds_since(t_iter);
    it.cumulative_time_s = seconds_since(t_start);
    summary.iterations.push_back(it);
    summary.final_cost = cost;

    if (!converged_message.empty())
      return finish(TerminationType::FunctionTolerance, converged_message);
    if (lambda > o.max_lambda)
      return finish(TerminationType::DampingLimit,
                    "lambda " + num(lambda) + " > max_lambda " + num(o.max_lambda) +
                        ": no step lowers the cost");
    if (o.callback && !o.callback(it))
      return finish(TerminationType::UserStop, "the callback asked to stop");
  }
}

SolverSummary solve(FactorGraph& graph, const SolverOptions& options) {
  Solver solver(options);
  return solver.solve(graph);
}

}  // namespace planarvo::graph
