// The odometry method of calibrate() (calibration.h; the paper's sec. 5.2.1, fig. 2): poses
// chained from odometry, an odometry factor (eq. 25) and a sensor factor (eq. 26) per interval
// on z; the robust pass, the gated least-squares passes, and the odometry's noise model fitted
// to the residuals where asked.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "graph/calibration/calibration_init.h"
#include "graph/calibration/calibration_internal.h"
#include "graph/calibration/odometry_noise.h"
#include "graph/solver/solver.h"

namespace planarvo::graph::calibration_detail {
namespace {

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
    if (!ctx.inlier[i]) {
      // A gated sample keeps neither factor: its odometry alone would only tie the two poses
      // together (it adds nothing about z), and a glitch of kilometres there would put lever
      // arms of that size into the normal equations. Fixing the next pose stands in for it as
      // the gauge of the poses after the gap.
      og.odometry_factor.push_back(-1);
      og.sensor_factor.push_back(-1);
      g.set_fixed(og.poses[i + 1]);
      continue;
    }
    og.odometry_factor.push_back(g.add_factor(
        std::make_unique<OdometryFactor>(og.poses[i], og.poses[i + 1], s.odometry->value,
                                         motion_information(ctx.odo_cov[i], s.odometry->value.theta)),
        kernel));
    og.sensor_factor.push_back(g.add_factor(
        std::make_unique<SensorMotionFactor>(og.poses[i], og.poses[i + 1], og.z, s.sensor.value,
                                             motion_information(ctx.sensor_cov[i], s.sensor.value.theta)),
        kernel));
  }
  return og;
}

// The start: the given initial value, else the closed form (calibration_init.h); the scale at
// fixed_scale when it is fixed.
Vector4 odometry_start(const Context& ctx) {
  const CalibrationOptions& o = ctx.options;
  Vector4 z;
  if (o.initial) {
    z = Vector4((*o.initial)[0], (*o.initial)[1], (*o.initial)[2], (*o.initial)[3]);
  } else {
    std::vector<SE2> robot, sensor;
    for (const MotionSample& s : ctx.samples) robot.push_back(s.odometry->value), sensor.push_back(s.sensor.value);
    const auto c = odometry_closed_form(robot, sensor, o.fix_scale, o.fixed_scale);
    z = Vector4(c[0], c[1], c[2], c[3]);
    if (!z.allFinite()) z = Vector4(0.0, 0.0, o.fix_scale ? o.fixed_scale : 1.0, 0.0);
  }
  if (o.fix_scale) z[CI::kHeight] = o.fixed_scale;
  return z;
}

// The passes of the odometry method. Each builds the graph anew (a gated sample loses its sensor
// factor) from the estimate and the poses of the pass before.
class OdometryPasses {
 public:
  explicit OdometryPasses(Context& ctx);
  // Plain least squares first from a given start, then the robust loss.
  void robust_pass();
  // Gating and plain least squares on the inliers, while the gate drops more.
  void gated_least_squares();
  // The odometry's noise model from the residuals, and the gated passes again with it.
  void refit_odometry_noise();
  // The variance factor, the covariance and the observability of the final fit.
  CalibrationResult finish();

 private:
  void solve_pass(RobustKernelPtr kernel);
  // Per inlier sample: the sensor and odometry factors' χ² together (3 dof once the two poses
  // are fitted).
  SampleResiduals sample_chi2() const;

  Context& ctx_;
  const CalibrationOptions& o_;
  const size_t n_;
  Vector4 z_;
  std::vector<SE2> poses_;
  OdometryGraph og_;
  bool solved_ = false;     // a pass has solved since the inliers last changed
  bool kernel_on_ = false;  // the last pass had the robust loss
};

OdometryPasses::OdometryPasses(Context& ctx)
    : ctx_(ctx), o_(ctx.options), n_(ctx.samples.size()), z_(odometry_start(ctx)), poses_{SE2()} {
  for (const MotionSample& s : ctx.samples) poses_.push_back(poses_.back() * s.odometry->value);
}

void OdometryPasses::solve_pass(RobustKernelPtr kernel) {
  for (int round = 0; round < 2; ++round) {
    og_ = build_odometry_graph(ctx_, poses_, z_, kernel);
    ctx_.record(solve(og_.graph, pass_options(o_, kernel != nullptr)));
    z_ = og_.graph.vector(og_.z);
    for (size_t i = 0; i < poses_.size(); ++i) poses_[i] = og_.graph.pose(og_.poses[i]);
    // (x, y, -s, yaw + pi) maps every sensor motion as (x, y, s, yaw) does: a half turn of the
    // sensor's frame negates its translations, as a negative scale does (eq. 20's model in
    // docs/conventions.md). A start far off in yaw can end on the negative branch; the same answer
    // with the height positive, solved there once more so that the graph (and the covariance
    // taken from it) is the positive one's. The robot's poses are the same on both.
    if (o_.fix_scale || z_[CI::kHeight] >= 0.0) return;
    z_[CI::kHeight] = -z_[CI::kHeight];
    z_[CI::kYaw] = wrap_angle(z_[CI::kYaw] + M_PI);
  }
}

SampleResiduals OdometryPasses::sample_chi2() const {
  SampleResiduals s;
  for (size_t i = 0; i < n_; ++i)
    if (og_.sensor_factor[i] >= 0) {
      s.chi2.push_back(factor_chi2(og_.graph, og_.sensor_factor[i]) +
                       factor_chi2(og_.graph, og_.odometry_factor[i]));
      s.sample.push_back(static_cast<int>(i));
    }
  return s;
}

void OdometryPasses::robust_pass() {
  if (o_.initial) {  // a far start: plain least squares first, so that the loss does not
    solve_pass(nullptr);  // take the good samples for outliers
    solved_ = true;
  } else {
    og_ = build_odometry_graph(ctx_, poses_, z_, nullptr);
  }
  if (o_.loss != RobustLoss::None) {
    const double k0 = std::max(1.0, median(sample_chi2().chi2) / kChi2Median3);  // the loss in the data's own sigmas
    solve_pass(make_kernel(o_.loss, o_.loss_scale * std::sqrt(k0)));
    solved_ = true;
    kernel_on_ = true;
  }
}

void OdometryPasses::gated_least_squares() {
  if (gated_passes(ctx_, kChi2Median3, [this] { return sample_chi2(); },
                   [this] { solve_pass(nullptr); }) > 0) {
    kernel_on_ = false;
    solved_ = true;
  }
  if (!solved_) solve_pass(nullptr);
}

// Where the samples' odometry carries no covariance of its own (odometry_noise.h): fitted twice,
// the second fit sees the estimate and the inliers of the first.
void OdometryPasses::refit_odometry_noise() {
  bool given = false;
  for (const MotionSample& s : ctx_.samples) given = given || s.odometry->has_covariance();
  if (!o_.estimate_odometry_noise || given) return;
  for (int round = 0; round < 2; ++round) {
    const SE2 T(z_[CI::kX], z_[CI::kY], z_[CI::kYaw]);
    const double h = z_[CI::kHeight];
    std::vector<SE2> odometry;
    std::vector<Eigen::Vector3d> residual;
    for (size_t i = 0; i < n_; ++i)
      if (ctx_.inlier[i]) {
        const SE2& ms = ctx_.samples[i].sensor.value;
        const SE2 mapped = T * SE2(h * ms.x, h * ms.y, ms.theta) * T.inverse();
        const SE2& mo = ctx_.samples[i].odometry->value;
        const SE2 e = mo.inverse() * mapped;
        odometry.push_back(mo);
        residual.emplace_back(e.x, e.y, e.theta);
      }
    ctx_.result.odometry_noise = fit_odometry_noise(odometry, residual);
    for (size_t i = 0; i < n_; ++i) {
      const SE2& mo = ctx_.samples[i].odometry->value;
      ctx_.odo_cov[i] = component_covariance(Motion{mo, ctx_.result.odometry_noise->covariance(mo)});
    }
    solved_ = false;
    gated_least_squares();
  }
}

CalibrationResult OdometryPasses::finish() {
  CalibrationResult& r = ctx_.result;
  const int inliers = static_cast<int>(std::count(ctx_.inlier.begin(), ctx_.inlier.end(), 1));
  const int free_z = o_.fix_scale ? 3 : 4;
  const int dof = 3 * inliers - free_z;
  const double fit = kernel_on_ ? median(sample_chi2().chi2) / kChi2Median3
                                : (dof > 0 ? og_.graph.chi2() / dof : 1.0);
  r.variance_factor = std::max(1.0, fit);
  r.estimated = {true, true, !o_.fix_scale, true};
  const Observability obs = covariance_of_z(og_.graph, og_.z, r.variance_factor, r);
  std::vector<int> params = {CI::kX, CI::kY};
  if (!o_.fix_scale) params.push_back(CI::kHeight);
  params.push_back(CI::kYaw);
  std::vector<std::string> reasons;
  judge(ctx_, obs, params, {CI::kX, CI::kY}, reasons);
  finish_result(ctx_, z_, reasons);
  return r;
}

}  // namespace

CalibrationResult calibrate_odometry(Context& ctx) {
  OdometryPasses passes(ctx);
  passes.robust_pass();
  passes.gated_least_squares();
  passes.refit_odometry_noise();
  return passes.finish();
}

}  // namespace planarvo::graph::calibration_detail
