// What the graph calibrations' files share (calibration.cpp, calibration_odometry.cpp,
// calibration_nonholonomic.cpp): the context of one calibrate() call, the robust pass and the
// gating, and the covariance and observability of z. Internal to src/graph.
#pragma once
#include <array>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "graph/calibration/calibration.h"
#include "graph/solver/factor_graph.h"
#include "graph/posegraph/factors.h"
#include "graph/calibration/factors.h"
#include "graph/solver/robust_kernel.h"

namespace planarvo::graph::calibration_detail {

using CI = CalibrationIndex;
using Vector4 = Eigen::Vector4d;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Medians of χ² with 1 and 3 degrees of freedom: the robust variance factor of a set of
// normalised squared residuals is their median over these.
constexpr double kChi2Median1 = 0.454936423119573, kChi2Median3 = 2.365973884375338;

inline double sq(double v) { return v * v; }
double median(std::vector<double> v);
// v with `digits` significant digits.
std::string num(double v, int digits = 3);

RobustKernelPtr make_kernel(RobustLoss loss, double c);
// eᵀΩe of one factor at the graph's values (no kernel).
double factor_chi2(const FactorGraph& g, int f);
// The solver's options for one pass: the user's, with a looser stop for the robust pass.
SolverOptions pass_options(const CalibrationOptions& o, bool robust);

// One calibrate() call: the input, the motions' covariances, which samples are inliers, and the
// result as it is filled in.
struct Context {
  const std::vector<MotionSample>& samples;
  const CalibrationOptions& options;
  std::vector<Eigen::Matrix3d> sensor_cov;  // of the sensor motion's (x, y, θ)
  std::vector<Eigen::Matrix3d> odo_cov;
  CalibrationResult result;
  std::vector<char> inlier;
  Context(const std::vector<MotionSample>& s, const CalibrationOptions& o);
  void record(const SolverSummary& s) {
    result.total_iterations += s.num_iterations;
    result.summary = s;
  }
  std::vector<SE2> inlier_sensor_motions(std::vector<double>* sigma_t,
                                         std::vector<double>* sigma_theta) const;
};

// The normalised squared residuals of the inlier samples of a graph, one per sample.
struct SampleResiduals {
  std::vector<double> chi2;
  std::vector<int> sample;  // the sample of each
};

// Gating (calibration.h, "Robustness"): at most 5 rounds that gate the samples on their
// residuals (`residuals`, with median chi2_median for their degrees of freedom) and solve the
// inliers by plain least squares (`solve_least_squares`), while the gate drops more; the first
// round always solves. Returns the number of solves, 0 without gating (gate_sigma 0).
int gated_passes(Context& ctx, double chi2_median, const std::function<SampleResiduals()>& residuals,
                 const std::function<void()>& solve_least_squares);

struct Observability {
  std::array<bool, 4> null_space{};
};

// Marginal covariance (scaled by f) and null space of z's free parameters in the final graph.
Observability covariance_of_z(const FactorGraph& g, VariableId z, double f, CalibrationResult& r);

// Observability of the parameters in `params` from the null space, the σ limits and the shape
// of the trajectory, with the reasons in words. `straight_params`: what driving straight leaves
// unobservable for this method.
void judge(Context& ctx, const Observability& obs, const std::vector<int>& params,
           const std::vector<int>& straight_params, std::vector<std::string>& reasons);

// The result's last fields: the gated samples, the value (yaw wrapped) and the reasons joined.
void finish_result(Context& ctx, const Vector4& z, const std::vector<std::string>& reasons);

// The two methods (calibration_odometry.cpp, calibration_nonholonomic.cpp).
CalibrationResult calibrate_odometry(Context& ctx);
CalibrationResult calibrate_nonholonomic(Context& ctx);

}  // namespace planarvo::graph::calibration_detail
