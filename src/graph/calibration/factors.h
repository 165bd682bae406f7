// The graph calibration's factors (paper sec. 5.2): the sensor's motions mapped through the
// calibration node (eq. 26), the nonholonomic constraint and the direction prior (eqs. 29-31).
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/se2.h"
#include "graph/solver/factor.h"

namespace planarvo::graph {

// ---- graph calibration (paper sec. 5.2) ------------------------------------------------------
//
// The calibration node z = (x, y, height, yaw): the sensor's pose T_vs = SE2(x, y, yaw) in the
// robot frame and the scale of its translations (the camera height for up-to-scale visual
// odometry; held fixed at 1 for a metric sensor). A sensor motion m_s maps into the robot frame
// as m_r = T_vs · S_h(m_s) · T_vs⁻¹, S_h scaling the translation by the height
// (docs/conventions.md).
struct CalibrationIndex {
  static constexpr int kX = 0, kY = 1, kHeight = 2, kYaw = 3, kDim = 4;
};
// Parameter names for FactorGraph::add_vector: {"x", "y", "height", "yaw"}.
std::vector<std::string> calibration_parameter_names();

// m_r for the calibration z (4 values) and, when dt_dz is not null, the 2×4 Jacobian of m_r's
// translation with respect to z (column-major). m_r's angle is m_s's, whatever z.
SE2 sensor_to_robot_motion(const SE2& sensor_motion, const double* z, double* dt_dz = nullptr);
// The same with cos and sin of the sensor motion's angle given (factors keep them).
SE2 sensor_to_robot_motion(const SE2& sensor_motion, double cos_theta, double sin_theta,
                           const double* z, double* dt_dz);

// The visual (sensor) odometry factor, eq. 26, between poses r_i, r_{i+1} and the calibration z:
// the robot's motion r_i⁻¹·r_{i+1} against the mapped sensor motion, e = t2v(m_r⁻¹·(r_i⁻¹·r_{i+1}))
// (eq. 26's ⊕ is a ⊖, as in eq. 25).
//
// Its information Ω_s is the sensor's, in the sensor's units. The paper weighs e with Ω_s
// projected by the current z (eq. 27: Ω̂ = Gᵀ Ω_s G, G = diag(1/h, 1/h, 1) · Ad(T_vs)⁻¹). This
// factor returns ẽ = G·e with Ω_s instead: the same cost eᵀΩ̂e at every z, and a Jacobian that
// includes how the projection moves with z, which a frozen Ω̂ would leave out (the solver would
// then stop where the two disagree). robot_frame_error() gives e itself.
class SensorMotionFactor final : public Factor {
 public:
  SensorMotionFactor(VariableId pose_i, VariableId pose_j, VariableId calibration,
                     const SE2& sensor_motion, const Eigen::Matrix3d& sensor_information);
  void evaluate(const double* const* values, double* error,
                double* const* jacobians) const override;
  // e of eq. 26 in the robot frame, at the given values (r_i, r_j, z).
  Eigen::Vector3d robot_frame_error(const double* const* values) const;
  const SE2& sensor_motion() const { return sensor_motion_; }

 private:
  SE2 sensor_motion_;
  double cm_, sm_;  // cos, sin of the measured angle
};

// The nonholonomic factor on z alone (paper sec. 5.2.2, in this project's conventions): the
// robot must not move sideways over an interval whose sensor motion is m_s.
//   Arc form (default), exact for a differential drive with constant (v, ω) over the interval:
//     e = m_r,y · cos(m_r,θ / 2) − m_r,x · sin(m_r,θ / 2)
//   Velocity form: e = m_r,y (the lateral motion; divide the information by Δt² for per time).
// Scale-free: it cannot tell the height from x (hold one of them), nor see y.
class NonholonomicFactor final : public Factor {
 public:
  enum class Form { Arc, Velocity };
  NonholonomicFactor(VariableId calibration, const SE2& sensor_motion, double information,
                     Form form = Form::Arc);
  void evaluate(const double* const* values, double* error,
                double* const* jacobians) const override;

 private:
  SE2 sensor_motion_;
  double nx_, ny_;  // e = n · t(m_r)
};

// The direction prior on z alone (paper eq. 31): whether the robot moved forwards (+1),
// backwards (−1) or not at all (0: standing or turning in place) over an interval. The error is
// the part of the forward motion m_r,x that contradicts the label: min(m_r,x, 0) for +1,
// max(m_r,x, 0) for −1, m_r,x for 0. Labels ±1 alone leave y in an interval (a flat-bottomed
// cost); 0 pins it. The cost has a kink where m_r,x changes sign.
class DirectionPriorFactor final : public Factor {
 public:
  DirectionPriorFactor(VariableId calibration, const SE2& sensor_motion, int direction,
                       double information);
  void evaluate(const double* const* values, double* error,
                double* const* jacobians) const override;

 private:
  SE2 sensor_motion_;
  int direction_;
};

}  // namespace planarvo::graph
