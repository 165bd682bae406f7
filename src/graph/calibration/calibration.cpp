// The graph calibrations (calibration.h), what both methods share: calibrate() and the
// validation of its input, the context of a call (the motions' covariances, the inliers), the
// robust pass's kernel and gating, and the covariance and observability judgement of z. The
// methods' graphs are in calibration_odometry.cpp and calibration_nonholonomic.cpp.
#include "graph/calibration/calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include "core/error.h"
#include "graph/calibration/calibration_init.h"
#include "graph/calibration/calibration_internal.h"
#include "graph/calibration/pair_residuals.h"
#include "graph/solver/covariance.h"

namespace planarvo::graph {
namespace calibration_detail {
namespace {

const char* const kNames[4] = {"x", "y", "scale", "yaw"};

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
  if (samples.empty()) throw_invalid_argument("graph calibration: no motion samples");
  for (size_t i = 0; i < samples.size(); ++i) {
    const MotionSample& s = samples[i];
    const std::string where = "graph calibration: motion sample " + std::to_string(i) + " (counting from 0): ";
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
  if (!positive(o.fixed_scale)) throw_invalid_argument("graph calibration: the fixed scale (camera height) must be positive");
  if (!non_negative(o.sensor_sigma_relative) || !non_negative(o.sensor_sigma_floor) ||
      !non_negative(o.odometry_sigma_relative) || !non_negative(o.odometry_sigma_floor) ||
      !positive(o.sensor_sigma_theta) || !positive(o.odometry_sigma_theta) ||
      !(o.sensor_sigma_floor > 0.0 || o.sensor_sigma_relative > 0.0) ||
      !(o.odometry_sigma_floor > 0.0 || o.odometry_sigma_relative > 0.0))
    throw_invalid_argument(
        "graph calibration: the default sigmas must be non-negative, the angle ones positive, and each "
        "translation model must have a positive floor or relative part");
  if (!positive(o.loss_scale)) throw_invalid_argument("graph calibration: the robust loss scale must be positive");
  if (!non_negative(o.gate_sigma)) throw_invalid_argument("graph calibration: the gate (sigmas) must be 0 or more");
  if (!non_negative(o.still_speed)) throw_invalid_argument("graph calibration: the still speed must be 0 or more");
  if (!positive(o.max_sigma_position) || !positive(o.max_sigma_angle) ||
      !positive(o.max_sigma_scale))
    throw_invalid_argument("graph calibration: the largest acceptable sigmas must be positive");
  if (o.initial) {
    for (double v : *o.initial)
      if (!std::isfinite(v)) throw_invalid_argument("graph calibration: the initial value is not finite");
    if (!o.fix_scale && o.method == CalibrationMethod::Odometry && !((*o.initial)[2] > 0.0))
      throw_invalid_argument("graph calibration: the initial scale must be positive");
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

std::vector<const double*> value_pointers(const FactorGraph& g, int f) {
  std::vector<const double*> p;
  for (VariableId v : g.factor(f).variables())
    p.push_back(&g.values()[static_cast<size_t>(g.offset(v))]);
  return p;
}

// Gates the samples whose normalised squared residual is beyond gate_sigma² times the robust
// variance factor where that exceeds 1; returns how many were newly gated.
int gate(Context& ctx, const SampleResiduals& residuals, double chi2_median) {
  const std::vector<double>& chi2 = residuals.chi2;
  const double k = median(chi2) / chi2_median;
  const double threshold = sq(ctx.options.gate_sigma) * std::max(k, 1.0);
  int gated = 0;
  for (size_t j = 0; j < chi2.size(); ++j)
    if (chi2[j] > threshold) {
      ctx.inlier[static_cast<size_t>(residuals.sample[j])] = 0;
      ++gated;
    }
  return gated;
}

double sigma_limit(const CalibrationOptions& o, int k) {
  return k == CI::kYaw ? o.max_sigma_angle : k == CI::kHeight ? o.max_sigma_scale : o.max_sigma_position;
}

}  // namespace

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

std::string num(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
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

Context::Context(const std::vector<MotionSample>& s, const CalibrationOptions& o)
    : samples(s), options(o), inlier(s.size(), 1) {
  for (const MotionSample& m : s) {
    sensor_cov.push_back(motion_covariance(m.sensor, o.sensor_sigma_relative, o.sensor_sigma_floor,
                                           o.sensor_sigma_theta));
    odo_cov.push_back(m.odometry ? motion_covariance(*m.odometry, o.odometry_sigma_relative,
                                                     o.odometry_sigma_floor, o.odometry_sigma_theta)
                                 : Eigen::Matrix3d(Eigen::Matrix3d::Identity()));
  }
}

std::vector<SE2> Context::inlier_sensor_motions(std::vector<double>* sigma_t,
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

int gated_passes(Context& ctx, double chi2_median, const std::function<SampleResiduals()>& residuals,
                 const std::function<void()>& solve_least_squares) {
  if (ctx.options.gate_sigma <= 0.0) return 0;
  int solves = 0;
  for (int round = 0; round < 5; ++round) {
    const int gated = gate(ctx, residuals(), chi2_median);
    if (round > 0 && gated == 0) break;
    solve_least_squares();
    ++solves;
  }
  return solves;
}

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

void judge(Context& ctx, const Observability& obs, const std::vector<int>& params,
           const std::vector<int>& straight_params, std::vector<std::string>& reasons) {
  CalibrationResult& r = ctx.result;
  std::vector<double> st, sth;
  const std::vector<SE2> motions = ctx.inlier_sensor_motions(&st, &sth);
  const TrajectoryShape shape = classify_trajectory(motions, st, sth);
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

void finish_result(Context& ctx, const Vector4& z, const std::vector<std::string>& reasons) {
  CalibrationResult& r = ctx.result;
  for (size_t i = 0; i < ctx.samples.size(); ++i)
    if (!ctx.inlier[i]) r.outlier_samples.push_back(static_cast<int>(i));
  r.outliers = static_cast<int>(r.outlier_samples.size());
  for (int k = 0; k < 4; ++k) r.value[static_cast<size_t>(k)] = z[k];
  r.value[CI::kYaw] = wrap_angle(z[CI::kYaw]);
  // Each pair's residual at the estimate, with the covariances the final solve weighed it by.
  r.residuals.assign(ctx.samples.size(), std::nullopt);
  for (size_t i = 0; i < ctx.samples.size(); ++i)
    if (ctx.samples[i].odometry)
      r.residuals[i] = pair_residual(ctx.samples[i].odometry->value, ctx.samples[i].sensor.value, ctx.odo_cov[i],
                                     ctx.sensor_cov[i], z);
  for (size_t k = 0; k < reasons.size(); ++k)
    r.unobservable_reason += (k ? "; " : "") + reasons[k];
}

}  // namespace calibration_detail

bool CalibrationResult::ok() const {
  if (!summary.converged() || ambiguous) return false;
  for (size_t k = 0; k < 4; ++k)
    if (estimated[k] && !observable[k]) return false;
  return true;
}

CalibrationResult calibrate(const std::vector<MotionSample>& samples,
                            const CalibrationOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  calibration_detail::validate(samples, options);
  calibration_detail::Context ctx(samples, options);
  CalibrationResult r = options.method == CalibrationMethod::Odometry
                            ? calibration_detail::calibrate_odometry(ctx)
                            : calibration_detail::calibrate_nonholonomic(ctx);
  r.total_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::vector<std::string> calibration_parameter_labels() { return {"x", "y", "scale", "yaw"}; }

}  // namespace planarvo::graph
