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
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/se2.h"
#include "graph/solver.h"

namespace planarvo::graph {

struct MotionSample {
  double interval = 0;           // seconds (> 0)
  SE2 sensor;                    // the sensor's motion in its own frame
  std::optional<SE2> odometry;   // the robot's motion from wheel odometry (method Odometry)
  std::optional<int> direction;  // +1 forwards, -1 backwards, 0 no linear motion
  // Optional per-sample uncertainties (e.g. the tracker's covariance); the options' defaults
  // are used where absent. Sensor: in the sensor's units; odometry: metres, radians.
  std::optional<Eigen::Matrix3d> sensor_covariance;
  std::optional<Eigen::Matrix3d> odometry_covariance;
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
  // Start of the solve: nullopt means a closed-form / grid initialisation of its own; given,
  // it is used as given (the paper started from x 0.2, y 0, z 0.2, yaw 0).
  std::optional<std::array<double, 4>> initial;  // x, y, scale, yaw
  // Default standard deviations where a sample carries no covariance: sensor per unit of
  // travel and per radian, wheel odometry likewise, plus floors.
  double sensor_sigma_relative = 0.01, sensor_sigma_floor = 1e-4;  // (sensor units)
  double sensor_sigma_theta = 1e-3;                                // rad
  double odometry_sigma_relative = 0.01, odometry_sigma_floor = 1e-4;  // m
  double odometry_sigma_theta = 2e-3;                                  // rad
  // Robustness against gross sensor errors (about 1% of scan matches fail on real data):
  // a redescending loss, or a first pass followed by gating residuals beyond gate_sigma.
  RobustLoss loss = RobustLoss::Cauchy;
  double loss_scale = 3.0;  // in standard deviations
  double gate_sigma = 5.0;  // 0: no gating pass
  // Nonholonomic residual: the exact arc form or the paper's velocity form.
  enum class NonholonomicForm { Arc, Velocity } nonholonomic_form = NonholonomicForm::Arc;
  // A parameter whose marginal standard deviation exceeds this (m or rad), or that lies in the
  // null space of the calibration block's information, is unobservable.
  double max_sigma_position = 0.05, max_sigma_angle = 0.05, max_sigma_scale = 0.05;
  SolverOptions solver;
};

struct CalibrationResult {
  // x, y (m), scale (camera height in m, or the fixed scale), yaw (rad). For the nonholonomic
  // method y comes from the direction labels (or stays at its initial value when there are
  // none, and is then not estimated).
  std::array<double, 4> value{};
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();  // order x, y, scale, yaw; 0 rows when not estimated
  std::array<bool, 4> estimated{};   // parameters the method estimated
  std::array<bool, 4> observable{};  // estimated and well determined
  // Why a parameter is unobservable, in words a user can act on ("driving straight only: x and
  // yaw are not observable; drive turns both ways", "one circle only", "no backward motion or
  // turning in place: y is not observable"). Empty when all estimated parameters are observable.
  std::string unobservable_reason;
  // Nonholonomic method without direction information: (x, yaw) and (-x, yaw + pi) fit equally;
  // value holds one branch, and this is set.
  bool ambiguous = false;
  int outliers = 0;  // samples gated out as gross errors
  SolverSummary summary;
  bool ok() const;   // converged, every estimated parameter observable, not ambiguous
};

// Throws Error(InvalidArgument) for unusable input (no samples, missing odometry for the
// Odometry method, non-positive intervals, non-finite values).
CalibrationResult calibrate(const std::vector<MotionSample>& samples, const CalibrationOptions& options);

std::vector<std::string> calibration_parameter_labels();  // {"x", "y", "scale", "yaw"}

}  // namespace planarvo::graph
