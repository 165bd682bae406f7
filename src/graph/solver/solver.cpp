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

namespace {

// One run of Levenberg–Marquardt on prepared normal equations, its loop in named steps as Ceres'
// TrustRegionMinimizer has them: linearise, solve the damped system, evaluate the step, update
// the trust region (λ). The state is what the steps share.
class LevenbergMarquardt {
 public:
  LevenbergMarquardt(NormalEquations& sys, const SolverOptions& o, FactorGraph& graph, SolverSummary& summary,
                     Clock::time_point t_start)
      : sys_(sys), o_(o), graph_(graph), summary_(summary), t_start_(t_start), x_(graph.values()), trial_(x_) {}

  SolverSummary run() {
    PhaseTimes& times = summary_.times;
    if (sys_.num_columns() == 0) {
      summary_.initial_cost = summary_.final_cost = sys_.evaluate_cost(x_.data(), &times);
      IterationSummary it0;
      it0.cost = summary_.initial_cost;
      summary_.iterations.push_back(it0);
      return finish(TerminationType::NothingToOptimize, "every variable is fixed");
    }
    linearise();
    summary_.initial_cost = summary_.final_cost = cost_;
    {
      IterationSummary it0;
      it0.cost = cost_;
      it0.gradient_max_norm = gmax_;
      it0.iteration_time_s = it0.cumulative_time_s = seconds_since(t_start_);
      summary_.iterations.push_back(it0);
    }
    if (!std::isfinite(cost_) || !std::isfinite(gmax_))
      return finish(TerminationType::NumericalFailure, "the cost or its gradient is not finite at the initial values");
    start_trust_region();
    for (int iter = 1;; ++iter) {
      if (gmax_ <= o_.gradient_tolerance)
        return finish(TerminationType::GradientTolerance,
                      "gradient max-norm " + num(gmax_) + " <= " + num(o_.gradient_tolerance));
      if (iter > o_.max_iterations)
        return finish(TerminationType::MaxIterations, "reached " + std::to_string(o_.max_iterations) + " iterations");
      if (seconds_since(t_start_) > o_.max_time_s)
        return finish(TerminationType::MaxTime, "exceeded " + num(o_.max_time_s) + " s");

      const auto t_iter = Clock::now();
      IterationSummary it;
      it.iteration = iter;
      it.lambda = lambda_;
      summary_.num_iterations = iter;
      const bool ok = solve_damped_system(it);
      std::string converged_message;  // set when the function tolerance is met
      if (ok) {
        double x_norm = 0.0;
        if (!evaluate_step(it, &x_norm, &converged_message)) {
          // A negligible step: converged at the current point, nothing to try or record.
          summary_.num_iterations = iter - 1;
          return finish(TerminationType::ParameterTolerance,
                        "step " + num(it.step_norm) + " <= parameter_tolerance * (|x| + tol) with |x| = " + num(x_norm));
        }
      }
      update_trust_region(it, ok);
      it.cost = cost_;
      it.gradient_max_norm = gmax_;
      it.iteration_time_s = seconds_since(t_iter);
      it.cumulative_time_s = seconds_since(t_start_);
      summary_.iterations.push_back(it);
      summary_.final_cost = cost_;

      if (!converged_message.empty()) return finish(TerminationType::FunctionTolerance, converged_message);
      if (lambda_ > o_.max_lambda)
        return finish(TerminationType::DampingLimit,
                      "lambda " + num(lambda_) + " > max_lambda " + num(o_.max_lambda) + ": no step lowers the cost");
      if (o_.callback && !o_.callback(it)) return finish(TerminationType::UserStop, "the callback asked to stop");
    }
  }

 private:
  // H, g and the cost at x.
  void linearise() {
    cost_ = sys_.linearize(x_.data(), &summary_.times);
    gmax_ = sys_.gradient().cwiseAbs().maxCoeff();
  }

  // The first λ, and the budget of factor reuse: CG iterations worth a fraction of a factorisation.
  void start_trust_region() {
    // λ in units of D: Levenberg's D = I needs the scale of H.
    lambda_scale_ = o_.damping == Damping::Levenberg ? std::max(sys_.hessian_diagonal().maxCoeff(), 1e-300) : 1.0;
    lambda_ = std::max(o_.initial_lambda * lambda_scale_, o_.min_lambda);
    nu_ = 2.0;
    cg_budget_ = o_.reuse_factorization
                     ? static_cast<int>(std::min<double>(
                           o_.reuse_max_cg_iterations,
                           std::floor(o_.reuse_cg_budget * sys_.factor_cost() / std::max(sys_.cg_iteration_cost(), 1.0))))
                     : 0;
  }

  // δ from (H + λD)δ = −g: by CG preconditioned with the last factor while that converges within
  // the budget, else by a new factorisation. False when neither gives a step.
  bool solve_damped_system(IterationSummary& it) {
    PhaseTimes& times = summary_.times;
    bool ok = false;
    if (cg_budget_ >= 2 && sys_.has_factor() && reuse_skip_-- <= 0) {
      it.cg_iterations =
          sys_.solve_step_reusing_factor(lambda_, o_.damping, delta_, cg_budget_, o_.reuse_cg_tolerance, &times);
      ok = it.cg_iterations > 0;
      if (ok) {
        reuse_backoff_ = 1;
      } else {
        // The factor no longer preconditions well: replace it now, and back off.
        reuse_skip_ = reuse_backoff_;
        reuse_backoff_ *= 2;
      }
    }
    if (!ok) {
      it.cg_iterations = 0;
      it.refactorized = true;
      ++summary_.num_factorizations;
      ok = sys_.factorize(lambda_, o_.damping, &times) && sys_.solve_step(delta_, &times);
      it.factorization_ok = ok;
    }
    return ok;
  }

  // The cost at x ⊞ δ against the decrease the model predicts (the gain ratio), and whether the
  // function tolerance is met. False, with |x| in *x_norm, when δ is negligible (converged).
  bool evaluate_step(IterationSummary& it, double* x_norm, std::string* converged_message) {
    it.step_norm = delta_.norm();
    *x_norm = sys_.free_values_norm(x_.data());
    if (it.step_norm <= o_.parameter_tolerance * (*x_norm + o_.parameter_tolerance)) return false;
    sys_.retract(x_.data(), delta_, trial_.data());
    const double new_cost = sys_.evaluate_cost(trial_.data(), &summary_.times);
    const double predicted =
        it.refactorized ? sys_.predicted_decrease_of_solution(delta_) : sys_.predicted_decrease(delta_);
    it.cost_change = cost_ - new_cost;
    it.relative_decrease = predicted > 0.0 ? it.cost_change / predicted : -1.0;
    it.step_accepted = std::isfinite(new_cost) && predicted > 0.0 && it.relative_decrease > o_.min_relative_decrease;
    if (std::isfinite(new_cost) && std::abs(it.cost_change) <= o_.function_tolerance * cost_)
      *converged_message = "relative cost change " + num(std::abs(it.cost_change) / std::max(cost_, 1e-300)) +
                           " <= " + num(o_.function_tolerance);
    return true;
  }

  // An accepted step moves x (linearised again there) and shrinks λ by the gain ratio (Nielsen's
  // rule); a rejected or failed one grows λ, doubling the factor each time.
  void update_trust_region(const IterationSummary& it, bool ok) {
    if (it.step_accepted) {
      ++summary_.num_accepted;
      x_.swap(trial_);
      linearise();
      const double r = 2.0 * it.relative_decrease - 1.0;
      lambda_ = std::max(lambda_ * std::max(1.0 / o_.lambda_max_decrease, 1.0 - r * r * r), o_.min_lambda);
      nu_ = 2.0;
    } else {
      if (ok)
        ++summary_.num_rejected;
      else
        ++summary_.num_failed_factorizations;
      // From λ = 0 (pure Gauss–Newton allowed by the options) doubling stays at 0: restart from a
      // small damping instead.
      lambda_ = lambda_ > 0.0 ? lambda_ * nu_ : 1e-8 * lambda_scale_;
      nu_ *= 2.0;
    }
  }

  SolverSummary finish(TerminationType type, std::string message) {
    summary_.termination = type;
    summary_.message = std::move(message);
    summary_.total_time_s = seconds_since(t_start_);
    graph_.set_values(x_);
    return summary_;
  }

  NormalEquations& sys_;
  const SolverOptions& o_;
  FactorGraph& graph_;
  SolverSummary& summary_;
  const Clock::time_point t_start_;
  std::vector<double> x_, trial_;
  double cost_ = 0.0, gmax_ = 0.0;
  double lambda_ = 0.0, lambda_scale_ = 1.0, nu_ = 2.0;
  int cg_budget_ = 0, reuse_skip_ = 0, reuse_backoff_ = 1;
  Eigen::VectorXd delta_;
};

}  // namespace

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
  return LevenbergMarquardt(sys, o, graph, summary, t_start).run();
}

SolverSummary solve(FactorGraph& graph, const SolverOptions& options) {
  Solver solver(options);
  return solver.solve(graph);
}

}  // namespace planarvo::graph
