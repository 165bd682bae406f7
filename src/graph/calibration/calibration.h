// The graph calibrations of the paper's section 5.2: the sensor's pose on the robot (x, y, yaw)
// and the scale of its translations (the camera height, for up-to-scale visual odometry) from
// its planar motions, (1) against wheel odometry (5.2.1, eqs. 25-27), or (2) with no odometry,
// from the nonholonomic constraint (5.2.2, eqs. 28-30 in this project's conventions) plus
// (3) direction labels (eq. 31) for y. Each returns the estimate, its marginal covariance,
// which parameters are observable (and why not), and the solver's summary.
//
// Input motions are planar relative motions of the sensor in its own frame, translation in its
// own units: metres for a metric sensor (a laser scan matcher; fix the scale at 1), units of the
// camera height for the tracker run with x = y = 0, z = 1, yaw = 0 (the height is then the scale).
// Intervals must turn less than half a turn (|θ| < π): beyond, driving forwards moves the robot
// backwards over the interval, and angles wrapped to (-π, π] cannot show it.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/motion.h"
#include "core/se2.h"
#include "graph/calibration/odometry_noise.h"
#include "graph/calibration/pair_residuals.h"
#include "graph/solver/solver.h"

namespace planarvo::graph {

// The motions carry optional covariances (core/motion.h: of the right perturbation; e.g. the
// tracker's); the options' noise model is used where a covariance is zero (not given).
struct MotionSample {
  double interval = 0;             // seconds (> 0)
  Motion sensor;                   // the sensor's motion in its own frame, in the sensor's units
  std::optional<Motion> odometry;  // the robot's motion from wheel odometry (method Odometry), m
  std::optional<int> direction;    // +1 forwards, -1 backwards, 0 no linear motion
};

enum class CalibrationMethod {
  Odometry,      // x, y, scale, yaw against wheel odometry; needs odometry on every sample
  Nonholonomic,  // x, yaw (and the branch) from the constraint; y from direction labels
};

enum class RobustLoss { None, Huber, Cauchy, Tukey };

struct CalibrationOptions {
  CalibrationMethod method = CalibrationMethod::Odometry;
  // Scale (height) held fixed at fixed_scale: a metric sensor (1), or a camera height measured
  // by hand (the nonholonomic method cannot estimate it: it is always fixed there).
  bool fix_scale = false;
  double fixed_scale = 1.0;
  // Start of the solve: nullopt means a closed-form initialisation of its own (exact on noise-free
  // motions; calibration_init.h); given, it is used as given (the paper started from x 0.2, y 0,
  // z 0.2, yaw 0), with a plain least-squares solve before the robust one. The nonholonomic
  // method takes x, y and yaw from it (its scale is fixed_scale).
  std::optional<std::array<double, 4>> initial;  // x, y, scale, yaw
  // Default standard deviations where a sample carries no covariance, of the motion's (x, y, θ)
  // components: translation σ_t² = floor² + (relative·|t|)², rotation
  // σ_θ² = sigma_theta² + (relative·|θ|)² (per unit of travel and per radian, plus floors).
  // Sensor in the sensor's units, odometry in metres and radians.
  double sensor_sigma_relative = 0.01, sensor_sigma_floor = 1e-4;  // (sensor units)
  double sensor_sigma_theta = 1e-3;                                // rad
  double odometry_sigma_relative = 0.01, odometry_sigma_floor = 1e-4;  // m
  double odometry_sigma_theta = 2e-3;                                  // rad
  // Odometry method, samples whose odometry carries no covariance: replace the model above by one
  // fitted to the calibration's own residuals (graph/odometry_noise.h: per component, a constant,
  // a part per travel and a part per turn, in the frame of the motion), then solve again. For a
  // sensor much more precise than the odometry, such as the tracked camera; the result's
  // covariance then reflects the odometry's actual noise rather than a guess.
  bool estimate_odometry_noise = false;
  // Robustness against gross sensor errors (about 1% of scan matches fail on real data): a first
  // solve with the robust loss, then gating: a sample whose normalised squared residual exceeds
  // gate_sigma² (times the residuals' own robust variance factor where that exceeds 1, so that
  // too optimistic sigmas do not gate good samples) is dropped, and the inliers are re-solved by
  // plain least squares (so the covariance is the least-squares one); repeated while the gate
  // drops more. gate_sigma 0: no gating, the loss stays on in the one solve.
  RobustLoss loss = RobustLoss::Cauchy;
  double loss_scale = 3.0;  // in standard deviations
  double gate_sigma = 5.0;  // 0: no gating pass
  // Direction labels of samples that carry odometry but no label (nonholonomic method): the sign
  // of the odometry's forward motion, 0 when slower than this (m/s), as io::read_motion_pairs.
  double still_speed = 1e-3;
  // Nonholonomic residual: the exact arc form, or the paper's velocity form (lateral motion),
  // which is biased where an interval turns (measured: ~0.5° of yaw and mm of x at 0.8 rad per
  // interval, about linear in the rotation per interval). Each residual is weighted by its
  // variance propagated from the sensor motion's covariance at the current z.
  enum class NonholonomicForm { Arc, Velocity } nonholonomic_form = NonholonomicForm::Arc;
  // A parameter whose marginal standard deviation exceeds this (m or rad), that lies in the null
  // space of the calibration block's information, or that the trajectory's shape leaves free
  // (driving straight only, one circle only: see CalibrationResult::unobservable_reason), is
  // unobservable.
  double max_sigma_position = 0.05, max_sigma_angle = 0.05, max_sigma_scale = 0.05;
  SolverOptions solver;
};

struct CalibrationResult {
  // x, y (m), scale (camera height in m, or the fixed scale), yaw (rad, wrapped to (-π, π]).
  // For the nonholonomic method y comes from the direction labels (or stays at its initial
  // value, 0 unless given, when there are none, and is then not estimated).
  std::array<double, 4> value{};
  // Order x, y, scale, yaw; rows and columns of parameters not estimated are zero. A parameter
  // in the null space of the calibration block's information has an infinite variance (and zero
  // covariances). Multiplied by variance_factor.
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  std::array<bool, 4> estimated{};   // parameters the method estimated
  std::array<bool, 4> observable{};  // estimated and well determined
  // Why a parameter is unobservable, in words a user can act on ("driving straight only (no
  // rotation): x and y are not observable; drive turns both ways", "one circle only", "no turning
  // in place (direction 0): the labels only bound y to [a, b] m"), and why the branch is
  // ambiguous. Empty when ok() or when the solver alone failed (see summary).
  std::string unobservable_reason;
  // Nonholonomic method without direction information: (x, yaw) and (-x, yaw + pi) fit equally;
  // value holds one branch, and this is set.
  bool ambiguous = false;
  int outliers = 0;                  // samples gated out as gross errors
  std::vector<int> outlier_samples;  // their indices in the input
  // Per sample, its residual at the estimate as the odometry method weighs it (pair_residuals.h,
  // with the covariances of the final solve); none for a sample without odometry.
  std::vector<std::optional<PairResidual>> residuals;
  // The a-posteriori variance factor max(1, χ²/dof) of the final least-squares fit (inliers):
  // the covariance is scaled by it, so sigmas that were too optimistic do not make it so.
  double variance_factor = 1.0;
  // Nonholonomic method with labels: samples labelled -1, 0, +1 (given, or from odometry), and
  // the interval of y where the direction prior (eq. 31) is at its minimum (one point when
  // labels 0 pin y; the interval the ±1 labels leave otherwise, ±infinity where unbounded).
  std::array<int, 3> direction_counts{};
  std::optional<std::array<double, 2>> y_interval;
  // The odometry noise model fitted when options.estimate_odometry_noise was used.
  std::optional<OdometryNoiseModel> odometry_noise;
  SolverSummary summary;      // the final solve's
  int total_iterations = 0;   // LM iterations over all solves (initial, robust, gated)
  double total_time_s = 0.0;  // calibrate() as a whole
  bool ok() const;   // converged, every estimated parameter observable, not ambiguous
};

// Throws Error(InvalidArgument) for unusable input (no samples, missing odometry for the
// Odometry method, non-positive intervals, non-finite values).
CalibrationResult calibrate(const std::vector<MotionSample>& samples, const CalibrationOptions& options);

std::vector<std::string> calibration_parameter_labels();  // {"x", "y", "scale", "yaw"}

}  // namespace planarvo::graph
