// The nonholonomic method of calibrate() (calibration.h; the paper's sec. 5.2.2, fig. 3): one
// nonholonomic factor per interval on (x, yaw), the branch that the direction labels vote for,
// and y from the direction prior (eq. 31) with x and yaw given.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "graph/calibration/calibration_init.h"
#include "graph/calibration/calibration_internal.h"
#include "graph/solver/solver.h"

namespace planarvo::graph::calibration_detail {
namespace {

using Form = CalibrationOptions::NonholonomicForm;
// Per sample: +1 forwards, -1 backwards, 0 turning in place, none where unknown.
using Labels = std::vector<std::optional<int>>;

// Variance of the nonholonomic residual of one interval from the sensor motion's covariance, at
// the calibration z: arc form e = −2 sin(θ/2) x + h n·R(γ) t, velocity form
// e = −sin θ x + (1 − cos θ) y + h (R(γ) t)_y.
double nonholonomic_variance(const SE2& m, const Eigen::Matrix3d& cov, const Vector4& z, Form form) {
  const double x = z[CI::kX], y = z[CI::kY], h = z[CI::kHeight], g = z[CI::kYaw];
  Eigen::RowVector3d J;
  if (form == Form::Arc) {
    const double half = 0.5 * m.theta;
    const double ux = std::cos(g) * m.x - std::sin(g) * m.y, uy = std::sin(g) * m.x + std::cos(g) * m.y;
    J << h * std::sin(g - half), h * std::cos(g - half),
        -std::cos(half) * x - 0.5 * h * (std::sin(half) * uy + std::cos(half) * ux);
  } else {
    J << h * std::sin(g), h * std::cos(g), -std::cos(m.theta) * x + std::sin(m.theta) * y;
  }
  return std::max(double(J * cov * J.transpose()), 1e-300);
}

// Variance of the robot's forward motion m_r,x = (1 − cos θ) x + sin θ y + h (R(γ) t)_x.
double forward_variance(const SE2& m, const Eigen::Matrix3d& cov, const Vector4& z) {
  const double g = z[CI::kYaw], h = z[CI::kHeight];
  Eigen::RowVector3d J;
  J << h * std::cos(g), -h * std::sin(g),
      std::sin(m.theta) * z[CI::kX] + std::cos(m.theta) * z[CI::kY];
  return std::max(double(J * cov * J.transpose()), 1e-300);
}

struct NonholonomicGraph {
  FactorGraph graph;
  VariableId z = -1;
  std::vector<int> factor_of;  // per sample, -1 when gated
};

NonholonomicGraph build_nonholonomic_graph(const Context& ctx, const Vector4& z,
                                           RobustKernelPtr kernel) {
  NonholonomicGraph ng;
  ng.z = ng.graph.add_vector(z, "z", calibration_parameter_names());
  ng.graph.set_parameter_fixed(ng.z, CI::kHeight);
  ng.graph.set_parameter_fixed(ng.z, CI::kY);  // not observable from the constraint
  const auto form = ctx.options.nonholonomic_form == Form::Arc ? NonholonomicFactor::Form::Arc
                                                                : NonholonomicFactor::Form::Velocity;
  for (size_t i = 0; i < ctx.samples.size(); ++i) {
    if (!ctx.inlier[i]) {
      ng.factor_of.push_back(-1);
      continue;
    }
    const SE2& m = ctx.samples[i].sensor.value;
    const double info = 1.0 / nonholonomic_variance(m, ctx.sensor_cov[i], z, ctx.options.nonholonomic_form);
    ng.factor_of.push_back(
        ng.graph.add_factor(std::make_unique<NonholonomicFactor>(ng.z, m, info, form), kernel));
  }
  return ng;
}

// Direction labels: given, else from the odometry's forward motion, else none.
Labels direction_labels(const Context& ctx) {
  Labels labels;
  for (const MotionSample& s : ctx.samples) {
    if (s.direction)
      labels.push_back(*s.direction);
    else if (s.odometry)
      labels.push_back(std::abs(s.odometry->value.x) < ctx.options.still_speed * s.interval
                           ? 0
                           : (s.odometry->value.x > 0.0 ? 1 : -1));
    else
      labels.push_back(std::nullopt);
  }
  return labels;
}

// The branch the ±1 labels vote for: +1 keep z, -1 flip it, 0 undecided (no decisive label, or
// labels that contradict each other). A label is decisive where the mapped forward motion is
// beyond 3 sigma of zero.
int branch_vote(const Context& ctx, const Labels& labels, const Vector4& z) {
  int agree = 0, disagree = 0;
  for (size_t i = 0; i < ctx.samples.size(); ++i) {
    if (!ctx.inlier[i] || !labels[i] || *labels[i] == 0) continue;
    const SE2& m = ctx.samples[i].sensor.value;
    const double fx = sensor_to_robot_motion(m, z.data()).x;
    if (sq(fx) <= 9.0 * forward_variance(m, ctx.sensor_cov[i], z)) continue;
    ((fx > 0.0) == (*labels[i] > 0) ? agree : disagree)++;
  }
  const int total = agree + disagree;
  if (total == 0) return 0;
  if (agree >= 0.75 * total) return 1;
  if (disagree >= 0.75 * total) return -1;
  return 0;
}

Vector4 flipped(const Vector4& z) {
  return Vector4(-z[CI::kX], -z[CI::kY], z[CI::kHeight], wrap_angle(z[CI::kYaw] + M_PI));
}

// The direction prior's terms (eq. 31) at z's x and yaw (y drops out of α), weighted at
// z_weights; sample_of: the sample of each term.
std::vector<PriorTerm> prior_terms(const Context& ctx, const Labels& labels, const Vector4& z,
                                   const Vector4& z_weights, std::vector<int>* sample_of = nullptr) {
  std::vector<PriorTerm> terms;
  if (sample_of) sample_of->clear();
  Vector4 z0 = z;
  z0[CI::kY] = 0.0;
  for (size_t i = 0; i < ctx.samples.size(); ++i) {
    if (!ctx.inlier[i] || !labels[i]) continue;
    const SE2& m = ctx.samples[i].sensor.value;
    PriorTerm t;
    t.alpha = sensor_to_robot_motion(m, z0.data()).x;
    t.beta = std::sin(m.theta);
    t.weight = 1.0 / forward_variance(m, ctx.sensor_cov[i], z_weights);
    t.label = *labels[i];
    terms.push_back(t);
    if (sample_of) sample_of->push_back(static_cast<int>(i));
  }
  return terms;
}

// The start: the given initial value, else the closed form (calibration_init.h) on the branch
// the labels vote for.
Vector4 nonholonomic_start(const Context& ctx, const Labels& labels) {
  const CalibrationOptions& o = ctx.options;
  const double h = o.fixed_scale;
  if (o.initial) return Vector4((*o.initial)[0], (*o.initial)[1], h, (*o.initial)[3]);
  std::vector<SE2> sensor;
  for (const MotionSample& s : ctx.samples) sensor.push_back(s.sensor.value);
  const auto c = nonholonomic_closed_form(sensor, h);
  Vector4 z(std::isfinite(c[0]) ? c[0] : 0.0, 0.0, h, std::isfinite(c[1]) ? c[1] : 0.0);
  if (branch_vote(ctx, labels, z) < 0) z = flipped(z);
  return z;
}

// ---- x and yaw from the nonholonomic constraint ----------------------------------------------

// The passes of the nonholonomic method on x and yaw. Each builds the graph anew (a gated sample
// loses its factor, the information depends on z) from the estimate of the pass before.
class NonholonomicPasses {
 public:
  NonholonomicPasses(Context& ctx, const Labels& labels)
      : ctx_(ctx), o_(ctx.options), labels_(labels), z_(nonholonomic_start(ctx, labels)) {}
  // Plain least squares first from a given start, the robust loss, then gating and plain least
  // squares on the inliers while the gate drops more.
  void solve_x_yaw();
  // The branch whose mapped forward motions agree with the labels (a flip maps every m_r,x to
  // −m_r,x and leaves the nonholonomic cost as it is).
  void choose_branch(std::vector<std::string>& reasons);
  // The variance factor, the covariance and the observability of x and yaw.
  void covariance(std::vector<std::string>& reasons);
  const Vector4& z() const { return z_; }

 private:
  void solve_pass(RobustKernelPtr kernel);
  SampleResiduals sample_chi2() const;
  void flip();

  Context& ctx_;
  const CalibrationOptions& o_;
  const Labels& labels_;
  Vector4 z_;
  NonholonomicGraph ng_;
  bool kernel_on_ = false;  // the last pass had the robust loss
};

void NonholonomicPasses::solve_pass(RobustKernelPtr kernel) {
  ng_ = build_nonholonomic_graph(ctx_, z_, kernel);
  ctx_.record(solve(ng_.graph, pass_options(o_, kernel != nullptr)));
  z_ = ng_.graph.vector(ng_.z);
}

SampleResiduals NonholonomicPasses::sample_chi2() const {
  SampleResiduals s;
  for (size_t i = 0; i < ctx_.samples.size(); ++i)
    if (ng_.factor_of[i] >= 0) {
      s.chi2.push_back(factor_chi2(ng_.graph, ng_.factor_of[i]));
      s.sample.push_back(static_cast<int>(i));
    }
  return s;
}

void NonholonomicPasses::flip() {
  z_ = flipped(z_);
  ng_.graph.set_vector(ng_.z, z_);
}

void NonholonomicPasses::solve_x_yaw() {
  if (o_.initial) solve_pass(nullptr);
  else ng_ = build_nonholonomic_graph(ctx_, z_, nullptr);
  double k0 = 1.0;
  if (o_.loss != RobustLoss::None) {
    k0 = std::max(1.0, median(sample_chi2().chi2) / kChi2Median1);
    solve_pass(make_kernel(o_.loss, o_.loss_scale * std::sqrt(k0)));
    kernel_on_ = true;
  }
  if (gated_passes(ctx_, kChi2Median1, [this] { return sample_chi2(); },
                   [this] { solve_pass(nullptr); }) > 0)
    kernel_on_ = false;
  // The information depends on z: once more with it taken at the solution.
  solve_pass(kernel_on_ ? make_kernel(o_.loss, o_.loss_scale * std::sqrt(k0)) : nullptr);
}

void NonholonomicPasses::choose_branch(std::vector<std::string>& reasons) {
  CalibrationResult& r = ctx_.result;
  const int vote = branch_vote(ctx_, labels_, z_);
  if (vote < 0) {
    flip();
  } else if (vote == 0) {
    r.ambiguous = true;
    // One branch by convention: the yaw nearer the given start's, else |yaw| ≤ π/2.
    const double ref = o_.initial ? (*o_.initial)[3] : 0.0;
    if (std::abs(wrap_angle(z_[CI::kYaw] - ref)) > 0.5 * M_PI) flip();
    reasons.push_back(
        r.direction_counts[0] + r.direction_counts[2] == 0
            ? "no forward or backward direction labels (+1/-1, given or from odometry): (x, yaw) "
              "and (-x, yaw + 180°) fit the nonholonomic constraint equally; give direction "
              "labels or odometry"
            : "the direction labels do not decide between (x, yaw) and (-x, yaw + 180°) (too few "
              "decisive labels, or contradicting ones); check the labels");
  }
}

void NonholonomicPasses::covariance(std::vector<std::string>& reasons) {
  CalibrationResult& r = ctx_.result;
  const std::vector<double> chi2 = sample_chi2().chi2;
  const int dof = static_cast<int>(chi2.size()) - 2;
  double sum = 0.0;
  for (double c : chi2) sum += c;
  r.variance_factor = std::max(1.0, kernel_on_ ? median(chi2) / kChi2Median1 : (dof > 0 ? sum / dof : 1.0));
  r.estimated = {true, false, false, true};
  const Observability obs = covariance_of_z(ng_.graph, ng_.z, r.variance_factor, r);
  judge(ctx_, obs, {CI::kX, CI::kYaw}, {CI::kX}, reasons);
}

// ---- y from the direction prior (eq. 31), x and yaw given -------------------------------------

struct PriorFit {
  PriorSolution solution;
  Vector4 z_weights;     // where the terms' weights were taken: y at the estimate
  double delta = 1.0;    // the variance factor of the residuals at the minimum
  int contradicted = 0;  // ±1 labels gated: contradicting their motions beyond the noise
};

// The residuals at the minimum y carry a χ² of their own: their variance factor widens the
// region. The labels 0 always; the ±1 labels that the minimum contradicts too, so that labels
// which contradict each other (wrong labels, or intervals turning more than half a turn, where
// driving forwards moves the robot backwards) widen y's σ instead of pinning it to a point
// between them. s0: the labels 0's normalised squared residuals.
double prior_variance_factor(const std::vector<PriorTerm>& terms, double y, std::vector<double>& s0) {
  double chi2_at_min = 0.0;
  int n_active = 0;
  for (const PriorTerm& t : terms) {
    const double e = t.alpha + t.beta * y;
    if (t.label == 0) s0.push_back(t.weight * e * e);
    if (prior_term_active(t, e)) chi2_at_min += t.weight * e * e, ++n_active;
  }
  return n_active >= 2 ? std::max(1.0, chi2_at_min / (n_active - 1)) : 1.0;
}

// Gates the samples of the terms whose residual at y is beyond gate_sigma² times the labels 0's
// robust variance factor where that exceeds 1; returns how many were gated.
int gate_prior(Context& ctx, const std::vector<PriorTerm>& terms, const std::vector<int>& term_sample,
               double y, const std::vector<double>& s0, int& contradicted) {
  const double k = s0.size() >= 5 ? median(s0) / kChi2Median1 : 1.0;
  const double threshold = sq(ctx.options.gate_sigma) * std::max(k, 1.0);
  int gated = 0;
  for (size_t j = 0; j < terms.size(); ++j) {
    const PriorTerm& t = terms[j];
    const double e = t.alpha + t.beta * y;
    if (prior_term_active(t, e) && t.weight * e * e > threshold) {
      ctx.inlier[static_cast<size_t>(term_sample[j])] = 0;
      ++gated;
      if (t.label != 0) ++contradicted;
    }
  }
  return gated;
}

// Weights at y = start, then at the estimate; then gating: a gross error on an interval turned
// in place can be invisible to the nonholonomic residual (it sees one direction of the
// translation) and still move y, so the prior's own residuals are gated like the constraint's,
// while the gate drops more.
PriorFit fit_direction_prior(Context& ctx, const Labels& labels, const Vector4& z) {
  PriorFit fit;
  fit.z_weights = z;
  std::vector<PriorTerm> terms;
  std::vector<int> term_sample;
  for (int pass = 0; pass < 6; ++pass) {
    terms = prior_terms(ctx, labels, z, fit.z_weights, &term_sample);
    fit.solution = solve_direction_prior(terms, 1.0);
    std::vector<double> s0;
    fit.delta = prior_variance_factor(terms, fit.solution.estimate, s0);
    if (fit.delta > 1.0) fit.solution = solve_direction_prior(terms, fit.delta);
    fit.z_weights[CI::kY] = fit.solution.estimate;
    if (pass == 0 || ctx.options.gate_sigma <= 0.0) continue;
    if (gate_prior(ctx, terms, term_sample, fit.solution.estimate, s0, fit.contradicted) == 0) break;
  }
  return fit;
}

// y's variance: the half width of the region within delta of the prior's minimum, squared, plus
// x's and yaw's covariance propagated to y by central differences of the whole 1-D solve.
void y_covariance(const Context& ctx, const Labels& labels, const Vector4& z, const PriorFit& fit,
                  Eigen::Matrix4d& cov) {
  const double half = 0.5 * (fit.solution.region_hi - fit.solution.region_lo);
  Eigen::RowVector2d J(0.0, 0.0);
  if (std::isfinite(half)) {
    const int idx[2] = {CI::kX, CI::kYaw};
    for (int k = 0; k < 2; ++k) {
      const double step = 1e-6;
      Vector4 zp = z, zm = z;
      zp[idx[k]] += step;
      zm[idx[k]] -= step;
      const double yp = solve_direction_prior(prior_terms(ctx, labels, zp, fit.z_weights), fit.delta).estimate;
      const double ym = solve_direction_prior(prior_terms(ctx, labels, zm, fit.z_weights), fit.delta).estimate;
      J[k] = (yp - ym) / (2.0 * step);
    }
  }
  Eigen::Matrix2d Cxg;
  Cxg << cov(CI::kX, CI::kX), cov(CI::kX, CI::kYaw), cov(CI::kYaw, CI::kX), cov(CI::kYaw, CI::kYaw);
  if (std::isfinite(half) && Cxg.allFinite()) {
    const Eigen::RowVector2d cross = J * Cxg;
    cov(CI::kY, CI::kY) = sq(half) + cross.dot(J);
    cov(CI::kY, CI::kX) = cov(CI::kX, CI::kY) = cross[0];
    cov(CI::kY, CI::kYaw) = cov(CI::kYaw, CI::kY) = cross[1];
  } else {
    cov(CI::kY, CI::kY) = kInf;
  }
}

// Whether y is observable, and why not in words.
void judge_y(const CalibrationOptions& o, const PriorFit& fit, CalibrationResult& r,
             std::vector<std::string>& reasons) {
  const double sigma_y = std::sqrt(r.covariance(CI::kY, CI::kY));
  r.observable[CI::kY] = sigma_y <= o.max_sigma_position;
  // Labels that contradict their motions beyond the noise are not gross sensor errors when
  // there are many: measured, 0-1 of thousands on the Censi files, 20-30% where intervals
  // turn more than half a turn. Gating them one by one would leave a consistent but wrong
  // subset (a confident wrong y), so y is not trusted then.
  const int plus_minus = r.direction_counts[0] + r.direction_counts[2];
  if (fit.contradicted > std::max(2, plus_minus / 100)) {
    r.observable[CI::kY] = false;
    reasons.push_back("y: " + std::to_string(fit.contradicted) + " of " + std::to_string(plus_minus) +
                      " direction labels contradict the motions (wrong labels, or intervals that "
                      "turn more than half a turn); check the labels, use shorter intervals");
  } else if (!r.observable[CI::kY]) {
    const int n0 = r.direction_counts[1];
    std::string why;
    if (n0 == 0) {
      why = "no turning in place (direction 0) among the labels: the ±1 labels only bound y to [" +
            num(fit.solution.argmin_lo, 4) + ", " + num(fit.solution.argmin_hi, 4) + "] m" +
            (std::isfinite(sigma_y) ? " (σ " + num(1000.0 * sigma_y) + " mm)" : std::string()) +
            "; turn in place (labelled 0), or drive tighter turns";
      if (r.direction_counts[0] == 0) why += "; there is no backward motion";
      if (r.direction_counts[2] == 0) why += "; there is no forward motion";
    } else {
      why = (std::isfinite(sigma_y)
                 ? "the labels 0 (turning in place) constrain y too weakly: σ(y) = " +
                       num(1000.0 * sigma_y) + " mm"
                 : std::string("the labels 0 do not constrain y (no rotation while labelled 0)")) +
            "; turn in place more, and turn while standing rather than stand still";
    }
    reasons.push_back("y: " + why);
  }
}

void estimate_y(Context& ctx, const Labels& labels, Vector4& z, std::vector<std::string>& reasons) {
  CalibrationResult& r = ctx.result;
  r.estimated[CI::kY] = true;
  const PriorFit fit = fit_direction_prior(ctx, labels, z);
  z[CI::kY] = fit.solution.estimate;
  r.y_interval = std::array<double, 2>{fit.solution.argmin_lo, fit.solution.argmin_hi};
  y_covariance(ctx, labels, z, fit, r.covariance);
  judge_y(ctx.options, fit, r, reasons);
}

}  // namespace

CalibrationResult calibrate_nonholonomic(Context& ctx) {
  CalibrationResult& r = ctx.result;
  const Labels labels = direction_labels(ctx);
  for (const auto& l : labels)
    if (l) r.direction_counts[static_cast<size_t>(*l + 1)]++;
  const bool have_labels = r.direction_counts[0] + r.direction_counts[1] + r.direction_counts[2] > 0;

  NonholonomicPasses passes(ctx, labels);
  passes.solve_x_yaw();
  std::vector<std::string> reasons;
  passes.choose_branch(reasons);
  passes.covariance(reasons);
  Vector4 z = passes.z();
  if (have_labels) estimate_y(ctx, labels, z, reasons);
  finish_result(ctx, z, reasons);
  return r;
}

}  // namespace planarvo::graph::calibration_detail
