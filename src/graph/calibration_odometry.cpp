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

#include "graph/calibration_init.h"
#include "graph/calibration_internal.h"
#include "graph/odometry_noise.h"
#include "graph/solver.h"

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

}  // namespace

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
    const auto c = odometry_closed_form(robot, sensor, o.fix_scale, o.fixed_scale);
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

}  // namespace planarvo::graph::calibration_detail
