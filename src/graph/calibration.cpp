// The graph calibrations (calibration.h): graphs of the paper's sec. 5.2 built from the factors of
// factors.h and solved by the sparse LM solver, with a closed-form start, a robust pass and
// gating, and the covariance and observability of z.
#include "graph/calibration.h"
#include "graph/odometry_noise.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "core/error.h"
#include "graph/calibration_init.h"
#include "graph/covariance.h"
#include "graph/factors.h"

namespace planarvo::graph {
namespace {

using CI = CalibrationIndex;
namespace cd = calibration_detail;
using Vector4 = Eigen::Vector4d;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Medians of χ² with 1 and 3 degrees of freedom: the robust variance factor of a set of
// normalised squared residuals is their median over these.
constexpr double kChi2Median1 = 0.454936423119573, kChi2Median3 = 2.365973884375338;
const char* const kNames[4] = {"x", "y", "scale", "yaw"};

double sq(double v) { return v * v; }

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// v with `digits` significant digits.
std::string num(double v, int digits = 3) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

std::string join_names(const std::vector<int>& params) {
  std::string s;
  for (size_t k = 0; k < params.size(); ++k) {
    if (k > 0) s += k + 1 == params.size() ? " and " : ", ";
    s += kNames[params[k]];
  }
  return s;
}

bool finite(const SE2& m) {
  return std::isfinite(m.x) && std::isfinite(m.y) && std::isfinite(m.theta);
}

bool spd(const Eigen::Matrix3d& c) {
  if (!c.allFinite() || !c.isApprox(c.transpose(), 1e-9)) return false;
  Eigen::LLT<Eigen::Matrix3d> llt(c);
  return llt.info() == Eigen::Success;
}

void validate(const std::vector<MotionSample>& samples, const CalibrationOptions& o) {
  if (samples.empty()) throw_invalid_argument("calibrate: no motion samples");
  for (size_t i = 0; i < samples.size(); ++i) {
    const MotionSample& s = samples[i];
    const std::string where = "calibrate: sample " + std::to_string(i) + ": ";
    if (!(s.interval > 0.0) || !std::isfinite(s.interval))
      throw_invalid_argument(where + "the interval must be positive and finite");
    if (!finite(s.sensor.value)) throw_invalid_argument(where + "the sensor motion is not finite");
    if (s.odometry && !finite(s.odometry->value))
      throw_invalid_argument(where + "the odometry motion is not finite");
    if (o.method == CalibrationMethod::Odometry && !s.odometry)
      throw_invalid_argument(where + "no odometry (the odometry method needs it on every sample)");
    if (s.direction && (*s.direction < -1 || *s.direction > 1))
      throw_invalid_argument(where + "the direction must be -1, 0 or +1");
    if (s.sensor.has_covariance() && !spd(s.sensor.covariance))
      throw_invalid_argument(where + "the sensor covariance is not symmetric positive definite");
    if (s.odometry && s.odometry->has_covariance() && !spd(s.odometry->covariance))
      throw_invalid_argument(where + "the odometry covariance is not symmetric positive definite");
  }
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  auto non_negative = [](double v) { return v >= 0.0 && std::isfinite(v); };
  if (!positive(o.fixed_scale)) throw_invalid_argument("calibrate: fixed_scale must be positive");
  if (!non_negative(o.sensor_sigma_relative) || !non_negative(o.sensor_sigma_floor) ||
      !non_negative(o.odometry_sigma_relative) || !non_negative(o.odometry_sigma_floor) ||
      !positive(o.sensor_sigma_theta) || !positive(o.odometry_sigma_theta) ||
      !(o.sensor_sigma_floor > 0.0 || o.sensor_sigma_relative > 0.0) ||
      !(o.odometry_sigma_floor > 0.0 || o.odometry_sigma_relative > 0.0))
    throw_invalid_argument(
        "calibrate: the default sigmas must be non-negative, the angle ones positive, and each "
        "translation model must have a positive floor or relative part");
  if (!positive(o.loss_scale)) throw_invalid_argument("calibrate: loss_scale must be positive");
  if (!non_negative(o.gate_sigma)) throw_invalid_argument("calibrate: gate_sigma must be >= 0");
  if (!non_negative(o.still_speed)) throw_invalid_argument("calibrate: still_speed must be >= 0");
  if (!positive(o.max_sigma_position) || !positive(o.max_sigma_angle) ||
      !positive(o.max_sigma_scale))
    throw_invalid_argument("calibrate: the max_sigma limits must be positive");
  if (o.initial) {
    for (double v : *o.initial)
      if (!std::isfinite(v)) throw_invalid_argument("calibrate: the initial value is not finite");
    if (!o.fix_scale && o.method == CalibrationMethod::Odometry && !((*o.initial)[2] > 0.0))
      throw_invalid_argument("calibrate: the initial scale must be positive");
  }
}

// Covariance of a motion's (x, y, θ) as numbers (what the factors and the variance propagation
// below take): the given one (of the right perturbation, so rotated into the motion's start
// frame), or the options' model (isotropic in translation: the same in either frame).
Eigen::Matrix3d motion_covariance(const Motion& m, double relative, double floor, double sigma_theta) {
  if (m.has_covariance()) return component_covariance(m);
  const double t2 = sq(floor) + sq(relative * std::hypot(m.value.x, m.value.y));
  const double r2 = sq(sigma_theta) + sq(relative * m.value.theta);
  return Eigen::Vector3d(t2, t2, r2).asDiagonal();
}

// Information of the error t2v(M⁻¹·X) for a motion M measured with covariance Σ of its
// (x, y, θ): M⁻¹·M' = (R(θ)ᵀ δt, δθ), so Ω = B Σ⁻¹ Bᵀ with B = diag(R(θ)ᵀ, 1).
Eigen::Matrix3d motion_information(const Eigen::Matrix3d& cov, double theta) {
  Eigen::Matrix3d B = Eigen::Matrix3d::Identity();
  B(0, 0) = B(1, 1) = std::cos(theta);
  B(0, 1) = std::sin(theta);
  B(1, 0) = -std::sin(theta);
  Eigen::Matrix3d info = B * cov.inverse() * B.transpose();
  return 0.5 * (info + info.transpose());
}

RobustKernelPtr make_kernel(RobustLoss loss, double c) {
  switch (loss) {
    case RobustLoss::Huber: return std::make_shared<HuberKernel>(c);
    case RobustLoss::Cauchy: return std::make_shared<CauchyKernel>(c);
    case RobustLoss::Tukey: return std::make_shared<TukeyKernel>(c);
    case RobustLoss::None: break;
  }
  return nullptr;
}

std::vector<const double*> value_pointers(const FactorGraph& g, int f) {
  std::vector<const double*> p;
  for (VariableId v : g.factor(f).variables())
    p.push_back(&g.values()[static_cast<size_t>(g.offset(v))]);
  return p;
}

// eᵀΩe of one factor at the graph's values (no kernel).
double factor_chi2(const FactorGraph& g, int f) {
  const Factor& fac = g.factor(f);
  const auto p = value_pointers(g, f);
  Eigen::VectorXd e(fac.residual_dim());
  fac.evaluate(p.data(), e.data(), nullptr);
  return e.dot(fac.information() * e);
}

// The robust pass before gating only has to tell the outliers: its iteratively reweighted steps
// converge linearly (on the Censi lmov data 50 iterations creep by 1e-5 of the cost each), so it
// stops at a relative cost change of 1e-4; the gated least-squares passes keep the user's options.
SolverOptions pass_options(const CalibrationOptions& o, bool robust) {
  SolverOptions s = o.solver;
  if (robust && o.gate_sigma > 0.0) s.function_tolerance = std::max(s.function_tolerance, 1e-4);
  return s;
}

struct Context {
  const std::vector<MotionSample>& samples;
  const CalibrationOptions& options;
  std::vector<Eigen::Matrix3d> sensor_cov;  // of the sensor motion's (x, y, θ)
  std::vector<Eigen::Matrix3d> odo_cov;
  CalibrationResult result;
  std::vector<char> inlier;
  Context(const std::vector<MotionSample>& s, const CalibrationOptions& o)
      : samples(s), options(o), inlier(s.size(), 1) {
    for (const MotionSample& m : s) {
      sensor_cov.push_back(motion_covariance(m.sensor, o.sensor_sigma_relative, o.sensor_sigma_floor,
                                             o.sensor_sigma_theta));
      odo_cov.push_back(m.odometry ? motion_covariance(*m.odometry, o.odometry_sigma_relative,
                                                       o.odometry_sigma_floor, o.odometry_sigma_theta)
                                   : Eigen::Matrix3d(Eigen::Matrix3d::Identity()));
    }
  }
  void record(const SolverSummary& s) {
    result.total_iterations += s.num_iterations;
    result.summary = s;
  }
  std::vector<SE2> inlier_sensor_motions(std::vector<double>* sigma_t,
                                         std::vector<double>* sigma_theta) const {
    std::vector<SE2> m;
    for (size_t i = 0; i < samples.size(); ++i)
      if (inlier[i]) {
        m.push_back(samples[i].sensor.value);
        sigma_t->push_back(std::sqrt(0.5 * (sensor_cov[i](0, 0) + sensor_cov[i](1, 1))));
        sigma_theta->push_back(std::sqrt(sensor_cov[i](2, 2)));
      }
    return m;
  }
};

// Gates the samples whose normalised squared residual (chi2, with median chi2_median for its
// degrees of freedom) is beyond gate_sigma² times the robust variance factor where that exceeds
// 1; returns how many were newly gated.
int gate(Context& ctx, const std::vector<double>& chi2, const std::vector<int>& sample_of,
         double chi2_median) {
  const double k = median(chi2) / chi2_median;
  const double threshold = sq(ctx.options.gate_sigma) * std::max(k, 1.0);
  int gated = 0;
  for (size_t j = 0; j < chi2.size(); ++j)
    if (chi2[j] > threshold) {
      ctx.inlier[static_cast<size_t>(sample_of[j])] = 0;
      ++gated;
    }
  return gated;
}

struct Observability {
  std::array<bool, 4> null_space{};
};

// Marginal covariance (scaled by f) and null space of z's free parameters in the final graph.
Observability covariance_of_z(const FactorGraph& g, VariableId z, double f, CalibrationResult& r) {
  Observability obs;
  const std::vector<std::string> gnames = calibration_parameter_names();
  auto index_of = [&](const std::string& name) {  // "z.height" → 2
    for (int k = 0; k < 4; ++k)
      if (name == g.name(z) + "." + gnames[static_cast<size_t>(k)]) return k;
    return -1;
  };
  std::vector<int> free;
  for (int k = 0; k < 4; ++k)
    if (!g.is_parameter_fixed(z, k)) free.push_back(k);
  Eigen::MatrixXd S;
  try {
    const ObservabilityReport rep = analyse_observability(g, {z});
    S = rep.information;
    for (const std::string& n : rep.unobservable) {
      const int k = index_of(n);
      if (k >= 0) obs.null_space[static_cast<size_t>(k)] = true;
    }
  } catch (const Error&) {
    for (int k : free) obs.null_space[static_cast<size_t>(k)] = true;
  }
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
  bool have = false;
  try {
    cov = MarginalCovariance(g, {z}).covariance(z);
    have = cov.allFinite();
  } catch (const Error&) {
  }
  if (!have && S.size() > 0) {
    // H is singular: the covariance of the parameters outside the null space from S restricted
    // to them (conditional on the others, which are infinite anyway).
    std::vector<int> keep;
    for (size_t j = 0; j < free.size(); ++j)
      if (!obs.null_space[static_cast<size_t>(free[j])]) keep.push_back(static_cast<int>(j));
    Eigen::MatrixXd Sk(keep.size(), keep.size());
    for (size_t a = 0; a < keep.size(); ++a)
      for (size_t b = 0; b < keep.size(); ++b) Sk(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = S(keep[a], keep[b]);
    const Eigen::MatrixXd Ck = Sk.size() > 0 ? Eigen::MatrixXd(Sk.inverse()) : Sk;
    for (size_t a = 0; a < keep.size(); ++a)
      for (size_t b = 0; b < keep.size(); ++b)
        cov(free[static_cast<size_t>(keep[a])], free[static_cast<size_t>(keep[b])]) =
            Ck(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  }
  cov *= f;
  for (int k = 0; k < 4; ++k)
    if (obs.null_space[static_cast<size_t>(k)] || !std::isfinite(cov(k, k)) || cov(k, k) < 0.0) {
      cov.row(k).setZero();
      cov.col(k).setZero();
      cov(k, k) = kInf;
      obs.null_space[static_cast<size_t>(k)] = true;
    }
  r.covariance = cov;
  return obs;
}

double sigma_limit(const CalibrationOptions& o, int k) {
  return k == CI::kYaw ? o.max_sigma_angle : k == CI::kHeight ? o.max_sigma_scale : o.max_sigma_position;
}

// Observability of the parameters in `params` from the null space, the σ limits and the shape
// of the trajectory, with the reasons in words. `straight_params`: what driving straight leaves
// unobservable for this method.
void judge(Context& ctx, const Observability& obs, const std::vector<int>& params,
           const std::vector<int>& straight_params, std::vector<std::string>& reasons) {
  CalibrationResult& r = ctx.result;
  std::vector<double> st, sth;
  const std::vector<SE2> motions = ctx.inlier_sensor_motions(&st, &sth);
  const cd::TrajectoryShape shape = cd::classify_trajectory(motions, st, sth);
  std::array<bool, 4> bad{};
  for (int k : params) r.observable[static_cast<size_t>(k)] = true;
  if (shape.straight_only) {
    reasons.push_back("driving straight only (no rotation): " + join_names(straight_params) +
                      (straight_params.size() > 1 ? " are" : " is") +
                      " not observable; drive turns both ways");
    for (int k : straight_params) bad[static_cast<size_t>(k)] = true;
  } else if (shape.one_circle) {
    reasons.push_back("one circle only (constant curvature, or turning in place only): " +
                      join_names(params) +
                      " are not observable together; drive turns of different curvature and "
                      "straight segments");
    for (int k : params) bad[static_cast<size_t>(k)] = true;
  }
  std::vector<int> null_params, loose;
  for (int k : params) {
    if (bad[static_cast<size_t>(k)]) continue;
    if (obs.null_space[static_cast<size_t>(k)]) {
      null_params.push_back(k);
      bad[static_cast<size_t>(k)] = true;
    } else if (!(std::sqrt(r.covariance(k, k)) <= sigma_limit(ctx.options, k))) {
      loose.push_back(k);
      bad[static_cast<size_t>(k)] = true;
    }
  }
  if (!null_params.empty())
    reasons.push_back("the motions do not determine " + join_names(null_params) +
                      " (null space of the information): drive turns both ways, of different "
                      "curvature, and straight segments");
  for (int k : loose) {
    const bool angle = k == CI::kYaw;
    const double unit = angle ? 180.0 / M_PI : 1000.0;
    const std::string u = angle ? "°" : " mm";
    reasons.push_back(std::string("σ(") + kNames[k] + ") = " +
                      num(unit * std::sqrt(r.covariance(k, k))) + u + " exceeds the limit " +
                      num(unit * sigma_limit(ctx.options, k)) + u +
                      ": record more motion, with turns both ways of different curvature");
  }
  for (int k : params)
    if (bad[static_cast<size_t>(k)]) r.observable[static_cast<size_t>(k)] = false;
}

// ---- odometry method (5.2.1) -------------------------------------------------------------

struct OdometryGraph {
  FactorGraph graph;
  VariableId z = -1;
  std::vector<VariableId> poses;
  std::vector<int> odometry_factor, sensor_factor;  // per sample; -1: gated out
};

OdometryGraph build_odometry_graph(const Context& ctx, const std::vector<SE2>& poses,
                                   const Vector4& z, RobustKernelPtr kernel) {
  OdometryGraph og;
  FactorGraph& g = og.graph;
  og.z = g.add_vector(z, "z", calibration_parameter_names());
  if (ctx.options.fix_scale) g.set_parameter_fixed(og.z, CI::kHeight);
  for (size_t i = 0; i < poses.size(); ++i)
    og.poses.push_back(g.add_pose(poses[i], "pose " + std::to_string(i)));
  g.set_fixed(og.poses[0]);
  for (size_t i = 0; i < ctx.samples.size(); ++i) {
    const MotionSample& s = ctx.samples[i];
    og.odometry_factor.push_back(g.add_factor(
        std::make_unique<OdometryFactor>(og.poses[i], og.poses[i + 1], s.odometry->value,
                                         motion_information(ctx.odo_cov[i], s.odometry->value.theta)),
        kernel));
    og.sensor_factor.push_back(
        ctx.inlier[i] ? g.add_factor(std::make_unique<SensorMotionFactor>(
                                         og.poses[i], og.poses[i + 1], og.z, s.sensor.value,
                                         motion_information(ctx.sensor_cov[i], s.sensor.value.theta)),
                                     kernel)
                      : -1);
  }
  return og;
}

CalibrationResult calibrate_odometry(Context& ctx) {
  const CalibrationOptions& o = ctx.options;
  const size_t n = ctx.samples.size();
  CalibrationResult& r = ctx.result;
  Vector4 z;
  if (o.initial) {
    z = Vector4((*o.initial)[0], (*o.initial)[1], (*o.initial)[2], (*o.initial)[3]);
  } else {
    std::vector<SE2> robot, sensor;
    for (const MotionSample& s : ctx.samples) robot.push_back(s.odometry->value), sensor.push_back(s.sensor.value);
    const auto c = cd::odometry_closed_form(robot, sensor, o.fix_scale, o.fixed_scale);
    z = Vector4(c[0], c[1], c[2], c[3]);
    if (!z.allFinite()) z = Vector4(0.0, 0.0, o.fix_scale ? o.fixed_scale : 1.0, 0.0);
  }
  if (o.fix_scale) z[CI::kHeight] = o.fixed_scale;
  std::vector<SE2> poses = {SE2()};
  for (const MotionSample& s : ctx.samples) poses.push_back(poses.back() * s.odometry->value);

  OdometryGraph og;
  auto solve_pass = [&](RobustKernelPtr kernel) {
    og = build_odometry_graph(ctx, poses, z, kernel);
    ctx.record(solve(og.graph, pass_options(o, kernel != nullptr)));
    z = og.graph.vector(og.z);
    for (size_t i = 0; i < poses.size(); ++i) poses[i] = og.graph.pose(og.poses[i]);
  };
  // Per inlier sample: the sensor and odometry factors' χ² together (3 dof once the two poses
  // are fitted).
  auto sample_chi2 = [&](std::vector<double>& chi2, std::vector<int>& sample_of) {
    chi2.clear();
    sample_of.clear();
    for (size_t i = 0; i < n; ++i)
      if (og.sensor_factor[i] >= 0) {
        chi2.push_back(factor_chi2(og.graph, og.sensor_factor[i]) +
                       factor_chi2(og.graph, og.odometry_factor[i]));
        sample_of.push_back(static_cast<int>(i));
      }
  };
  std::vector<double> chi2;
  std::vector<int> sample_of;
  bool solved = false;
  if (o.initial) {  // a far start: plain least squares first, so that the loss does not
    solve_pass(nullptr);  // take the good samples for outliers
    solved = true;
  } else {
    og = build_odometry_graph(ctx, poses, z, nullptr);
  }
  double k0 = 1.0;
  if (o.loss != RobustLoss::None) {
    sample_chi2(chi2, sample_of);
    k0 = std::max(1.0, median(chi2) / kChi2Median3);  // the loss in the data's own sigmas
    solve_pass(make_kernel(o.loss, o.loss_scale * std::sqrt(k0)));
    solved = true;
  }
  bool kernel_on = o.loss != RobustLoss::None;
  auto gated_least_squares = [&] {
    if (o.gate_sigma > 0.0) {
      for (int round = 0; round < 5; ++round) {
        sample_chi2(chi2, sample_of);
        const int gated = gate(ctx, chi2, sample_of, kChi2Median3);
        if (round > 0 && gated == 0) break;
        solve_pass(nullptr);
        kernel_on = false;
        solved = true;
      }
    }
    if (!solved) solve_pass(nullptr);
  };
  gated_least_squares();
  // The odometry's own noise model from the inliers' residuals (odometry_noise.h), twice: the
  // second fit sees the estimate and the inliers of the first.
  bool given = false;
  for (const MotionSample& s : ctx.samples) given = given || s.odometry->has_covariance();
  if (o.estimate_odometry_noise && !given) {
    for (int round = 0; round < 2; ++round) {
      const SE2 T(z[CI::kX], z[CI::kY], z[CI::kYaw]);
      const double h = z[CI::kHeight];
      std::vector<SE2> odometry;
      std::vector<Eigen::Vector3d> residual;
      for (size_t i = 0; i < n; ++i)
        if (ctx.inlier[i]) {
          const SE2& ms = ctx.samples[i].sensor.value;
          const SE2 mapped = T * SE2(h * ms.x, h * ms.y, ms.theta) * T.inverse();
          const SE2& mo = ctx.samples[i].odometry->value;
          const SE2 e = mo.inverse() * mapped;
          odometry.push_back(mo);
          residual.emplace_back(e.x, e.y, e.theta);
        }
      r.odometry_noise = fit_odometry_noise(odometry, residual);
      for (size_t i = 0; i < n; ++i) {
        const SE2& mo = ctx.samples[i].odometry->value;
        ctx.odo_cov[i] = component_covariance(Motion{mo, r.odometry_noise->covariance(mo)});
      }
      solved = false;
      gated_least_squares();
    }
  }

  for (size_t i = 0; i < n; ++i)
    if (!ctx.inlier[i]) r.outlier_samples.push_back(static_cast<int>(i));
  r.outliers = static_cast<int>(r.outlier_samples.size());
  const int free_z = o.fix_scale ? 3 : 4;
  const int dof = 3 * (static_cast<int>(n) - r.outliers) - free_z;
  sample_chi2(chi2, sample_of);
  const double fit = kernel_on ? median(chi2) / kChi2Median3
                               : (dof > 0 ? og.graph.chi2() / dof : 1.0);
  r.variance_factor = std::max(1.0, fit);
  for (int k = 0; k < 4; ++k) r.value[static_cast<size_t>(k)] = z[k];
  r.value[CI::kYaw] = wrap_angle(z[CI::kYaw]);
  r.estimated = {true, true, !o.fix_scale, true};
  const Observability obs = covariance_of_z(og.graph, og.z, r.variance_factor, r);
  std::vector<int> params = {CI::kX, CI::kY};
  if (!o.fix_scale) params.push_back(CI::kHeight);
  params.push_back(CI::kYaw);
  std::vector<std::string> reasons;
  judge(ctx, obs, params, {CI::kX, CI::kY}, reasons);
  for (size_t k = 0; k < reasons.size(); ++k)
    r.unobservable_reason += (k ? "; " : "") + reasons[k];
  return r;
}

// ---- nonholonomic method (5.2.2) and direction prior (eq. 31) ------------------------------

using Form = CalibrationOptions::NonholonomicForm;

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
std::vector<std::optional<int>> direction_labels(const Context& ctx) {
  std::vector<std::optional<int>> labels;
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
int branch_vote(const Context& ctx, const std::vector<std::optional<int>>& labels, const Vector4& z) {
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

struct PriorEstimate {
  cd::PriorSolution solution;
  double sigma = kInf;  // from the cost's one-sigma region alone
};

std::vector<cd::PriorTerm> prior_terms(const Context& ctx, const std::vector<std::optional<int>>& labels,
                                       const Vector4& z, const Vector4& z_weights,
                                       std::vector<int>* sample_of = nullptr) {
  std::vector<cd::PriorTerm> terms;
  if (sample_of) sample_of->clear();
  Vector4 z0 = z;
  z0[CI::kY] = 0.0;
  for (size_t i = 0; i < ctx.samples.size(); ++i) {
    if (!ctx.inlier[i] || !labels[i]) continue;
    const SE2& m = ctx.samples[i].sensor.value;
    cd::PriorTerm t;
    t.alpha = sensor_to_robot_motion(m, z0.data()).x;
    t.beta = std::sin(m.theta);
    t.weight = 1.0 / forward_variance(m, ctx.sensor_cov[i], z_weights);
    t.label = *labels[i];
    terms.push_back(t);
    if (sample_of) sample_of->push_back(static_cast<int>(i));
  }
  return terms;
}

CalibrationResult calibrate_nonholonomic(Context& ctx) {
  const CalibrationOptions& o = ctx.options;
  CalibrationResult& r = ctx.result;
  const size_t n = ctx.samples.size();
  const double h = o.fixed_scale;
  const auto labels = direction_labels(ctx);
  for (const auto& l : labels)
    if (l) r.direction_counts[static_cast<size_t>(*l + 1)]++;
  const bool have_labels = r.direction_counts[0] + r.direction_counts[1] + r.direction_counts[2] > 0;

  Vector4 z;
  if (o.initial) {
    z = Vector4((*o.initial)[0], (*o.initial)[1], h, (*o.initial)[3]);
  } else {
    std::vector<SE2> sensor;
    for (const MotionSample& s : ctx.samples) sensor.push_back(s.sensor.value);
    const auto c = cd::nonholonomic_closed_form(sensor, h);
    z = Vector4(std::isfinite(c[0]) ? c[0] : 0.0, 0.0, h, std::isfinite(c[1]) ? c[1] : 0.0);
    if (branch_vote(ctx, labels, z) < 0) z = flipped(z);
  }

  NonholonomicGraph ng;
  auto solve_pass = [&](RobustKernelPtr kernel) {
    ng = build_nonholonomic_graph(ctx, z, kernel);
    ctx.record(solve(ng.graph, pass_options(o, kernel != nullptr)));
    z = ng.graph.vector(ng.z);
  };
  auto sample_chi2 = [&](std::vector<double>& chi2, std::vector<int>& sample_of) {
    chi2.clear();
    sample_of.clear();
    for (size_t i = 0; i < n; ++i)
      if (ng.factor_of[i] >= 0) {
        chi2.push_back(factor_chi2(ng.graph, ng.factor_of[i]));
        sample_of.push_back(static_cast<int>(i));
      }
  };
  std::vector<double> chi2;
  std::vector<int> sample_of;
  if (o.initial) solve_pass(nullptr);
  else ng = build_nonholonomic_graph(ctx, z, nullptr);
  bool kernel_on = false;
  double k0 = 1.0;
  if (o.loss != RobustLoss::None) {
    sample_chi2(chi2, sample_of);
    k0 = std::max(1.0, median(chi2) / kChi2Median1);
    solve_pass(make_kernel(o.loss, o.loss_scale * std::sqrt(k0)));
    kernel_on = true;
  }
  if (o.gate_sigma > 0.0) {
    for (int round = 0; round < 5; ++round) {
      sample_chi2(chi2, sample_of);
      const int gated = gate(ctx, chi2, sample_of, kChi2Median1);
      if (round > 0 && gated == 0) break;
      solve_pass(nullptr);
      kernel_on = false;
    }
  }
  // The information depends on z: once more with it taken at the solution.
  solve_pass(kernel_on ? make_kernel(o.loss, o.loss_scale * std::sqrt(k0)) : nullptr);

  // The branch: the one whose mapped forward motions agree with the labels (a flip maps every
  // m_r,x to −m_r,x and leaves the nonholonomic cost as it is).
  std::vector<std::string> reasons;
  const int vote = branch_vote(ctx, labels, z);
  if (vote < 0) {
    z = flipped(z);
    ng.graph.set_vector(ng.z, z);
  } else if (vote == 0) {
    r.ambiguous = true;
    // One branch by convention: the yaw nearer the given start's, else |yaw| ≤ π/2.
    const double ref = o.initial ? (*o.initial)[3] : 0.0;
    if (std::abs(wrap_angle(z[CI::kYaw] - ref)) > 0.5 * M_PI) {
      z = flipped(z);
      ng.graph.set_vector(ng.z, z);
    }
    reasons.push_back(
        r.direction_counts[0] + r.direction_counts[2] == 0
            ? "no forward or backward direction labels (+1/-1, given or from odometry): (x, yaw) "
              "and (-x, yaw + 180°) fit the nonholonomic constraint equally; give direction "
              "labels or odometry"
            : "the direction labels do not decide between (x, yaw) and (-x, yaw + 180°) (too few "
              "decisive labels, or contradicting ones); check the labels");
  }

  sample_chi2(chi2, sample_of);
  const int dof = static_cast<int>(chi2.size()) - 2;
  double sum = 0.0;
  for (double c : chi2) sum += c;
  r.variance_factor = std::max(1.0, kernel_on ? median(chi2) / kChi2Median1 : (dof > 0 ? sum / dof : 1.0));
  r.estimated = {true, false, false, true};
  const Observability obs = covariance_of_z(ng.graph, ng.z, r.variance_factor, r);
  judge(ctx, obs, {CI::kX, CI::kYaw}, {CI::kX}, reasons);

  // y from the direction prior (eq. 31), x and yaw given.
  if (have_labels) {
    r.estimated[CI::kY] = true;
    Vector4 zw = z;
    cd::PriorSolution sol;
    std::vector<cd::PriorTerm> terms;
    std::vector<int> term_sample;
    double delta = 1.0;
    int contradicted = 0;  // ±1 labels gated: contradicting their motions beyond the noise
    // Weights at y = start, then at the estimate; then gating: a gross error on an interval
    // turned in place can be invisible to the nonholonomic residual (it sees one direction of
    // the translation) and still move y, so the prior's own residuals are gated like the
    // constraint's, while the gate drops more.
    for (int pass = 0; pass < 6; ++pass) {
      terms = prior_terms(ctx, labels, z, zw, &term_sample);
      sol = cd::solve_direction_prior(terms, 1.0);
      // The residuals at the minimum carry a χ² of their own: their variance factor widens the
      // region. The labels 0 always; the ±1 labels that the minimum contradicts too, so that
      // labels which contradict each other (wrong labels, or intervals turning more than half a
      // turn, where driving forwards moves the robot backwards) widen y's σ instead of pinning
      // it to a point between them.
      std::vector<double> s0;
      double chi2_at_min = 0.0;
      int n_active = 0;
      for (const cd::PriorTerm& t : terms) {
        const double e = t.alpha + t.beta * sol.estimate;
        if (t.label == 0) s0.push_back(t.weight * e * e);
        if (t.label == 0 || (t.label > 0 ? e < 0.0 : e > 0.0)) chi2_at_min += t.weight * e * e, ++n_active;
      }
      delta = n_active >= 2 ? std::max(1.0, chi2_at_min / (n_active - 1)) : 1.0;
      if (delta > 1.0) sol = cd::solve_direction_prior(terms, delta);
      zw[CI::kY] = sol.estimate;
      if (pass == 0 || o.gate_sigma <= 0.0) continue;
      const double k = s0.size() >= 5 ? median(s0) / kChi2Median1 : 1.0;
      const double threshold = sq(o.gate_sigma) * std::max(k, 1.0);
      int gated = 0;
      for (size_t j = 0; j < terms.size(); ++j) {
        const cd::PriorTerm& t = terms[j];
        const double e = t.alpha + t.beta * sol.estimate;
        const bool active = t.label == 0 || (t.label > 0 ? e < 0.0 : e > 0.0);
        if (active && t.weight * e * e > threshold) {
          ctx.inlier[static_cast<size_t>(term_sample[j])] = 0;
          ++gated;
          if (t.label != 0) ++contradicted;
        }
      }
      if (gated == 0) break;
    }
    z[CI::kY] = sol.estimate;
    r.y_interval = std::array<double, 2>{sol.argmin_lo, sol.argmin_hi};
    const double half = 0.5 * (sol.region_hi - sol.region_lo);
    // How y moves with x and yaw (central differences of the whole 1-D solve).
    Eigen::RowVector2d J(0.0, 0.0);
    if (std::isfinite(half)) {
      const int idx[2] = {CI::kX, CI::kYaw};
      for (int k = 0; k < 2; ++k) {
        const double step = 1e-6;
        Vector4 zp = z, zm = z;
        zp[idx[k]] += step;
        zm[idx[k]] -= step;
        const double yp = cd::solve_direction_prior(prior_terms(ctx, labels, zp, zw), delta).estimate;
        const double ym = cd::solve_direction_prior(prior_terms(ctx, labels, zm, zw), delta).estimate;
        J[k] = (yp - ym) / (2.0 * step);
      }
    }
    Eigen::Matrix2d Cxg;
    Cxg << r.covariance(CI::kX, CI::kX), r.covariance(CI::kX, CI::kYaw),
        r.covariance(CI::kYaw, CI::kX), r.covariance(CI::kYaw, CI::kYaw);
    if (std::isfinite(half) && Cxg.allFinite()) {
      const Eigen::RowVector2d cross = J * Cxg;
      r.covariance(CI::kY, CI::kY) = sq(half) + cross.dot(J);
      r.covariance(CI::kY, CI::kX) = r.covariance(CI::kX, CI::kY) = cross[0];
      r.covariance(CI::kY, CI::kYaw) = r.covariance(CI::kYaw, CI::kY) = cross[1];
    } else {
      r.covariance(CI::kY, CI::kY) = kInf;
    }
    const double sigma_y = std::sqrt(r.covariance(CI::kY, CI::kY));
    r.observable[CI::kY] = sigma_y <= o.max_sigma_position;
    // Labels that contradict their motions beyond the noise are not gross sensor errors when
    // there are many: measured, 0-1 of thousands on the Censi files, 20-30% where intervals
    // turn more than half a turn. Gating them one by one would leave a consistent but wrong
    // subset (a confident wrong y), so y is not trusted then.
    const int plus_minus = r.direction_counts[0] + r.direction_counts[2];
    if (contradicted > std::max(2, plus_minus / 100)) {
      r.observable[CI::kY] = false;
      reasons.push_back("y: " + std::to_string(contradicted) + " of " + std::to_string(plus_minus) +
                        " direction labels contradict the motions (wrong labels, or intervals that "
                        "turn more than half a turn); check the labels, use shorter intervals");
    } else if (!r.observable[CI::kY]) {
      const int n0 = r.direction_counts[1];
      std::string why;
      if (n0 == 0) {
        why = "no turning in place (direction 0) among the labels: the ±1 labels only bound y to [" +
              num(sol.argmin_lo, 4) + ", " + num(sol.argmin_hi, 4) + "] m" +
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
  for (size_t i = 0; i < n; ++i)
    if (!ctx.inlier[i]) r.outlier_samples.push_back(static_cast<int>(i));
  r.outliers = static_cast<int>(r.outlier_samples.size());
  for (int k = 0; k < 4; ++k) r.value[static_cast<size_t>(k)] = z[k];
  r.value[CI::kYaw] = wrap_angle(z[CI::kYaw]);
  for (size_t k = 0; k < reasons.size(); ++k)
    r.unobservable_reason += (k ? "; " : "") + reasons[k];
  return r;
}

}  // namespace

bool CalibrationResult::ok() const {
  if (!summary.converged() || ambiguous) return false;
  for (size_t k = 0; k < 4; ++k)
    if (estimated[k] && !observable[k]) return false;
  return true;
}

CalibrationResult calibrate(const std::vector<MotionSample>& samples,
                            const CalibrationOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  validate(samples, options);
  Context ctx(samples, options);
  CalibrationResult r = options.method == CalibrationMethod::Odometry ? calibrate_odometry(ctx)
                                                                      : calibrate_nonholonomic(ctx);
  r.total_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::vector<std::string> calibration_parameter_labels() { return {"x", "y", "scale", "yaw"}; }

}  // namespace planarvo::graph
