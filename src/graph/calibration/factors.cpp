#include "graph/calibration/factors.h"

#include <cmath>

#include "core/error.h"

namespace planarvo::graph {

std::vector<std::string> calibration_parameter_names() { return {"x", "y", "height", "yaw"}; }

SE2 sensor_to_robot_motion(const SE2& m, const double* z, double* dt_dz) {
  return sensor_to_robot_motion(m, std::cos(m.theta), std::sin(m.theta), z, dt_dz);
}

SE2 sensor_to_robot_motion(const SE2& m, double cp, double sp, const double* z, double* dt_dz) {
  const double x = z[CalibrationIndex::kX], y = z[CalibrationIndex::kY];
  const double h = z[CalibrationIndex::kHeight], yaw = z[CalibrationIndex::kYaw];
  const double cg = std::cos(yaw), sg = std::sin(yaw);
  // T·S_h(m)·T⁻¹ = (R_φ, (I − R_φ)·p + h·R_γ·v): planar rotations commute.
  const double rvx = cg * m.x - sg * m.y, rvy = sg * m.x + cg * m.y;
  const double tx = (1.0 - cp) * x + sp * y + h * rvx;
  const double ty = -sp * x + (1.0 - cp) * y + h * rvy;
  if (dt_dz) {
    Eigen::Map<Eigen::Matrix<double, 2, 4>> J(dt_dz);
    J << 1.0 - cp, sp, rvx, -h * rvy,  //
        -sp, 1.0 - cp, rvy, h * rvx;
  }
  return {tx, ty, m.theta};
}

SensorMotionFactor::SensorMotionFactor(VariableId pose_i, VariableId pose_j,
                                       VariableId calibration, const SE2& sensor_motion,
                                       const Eigen::Matrix3d& sensor_information)
    : Factor({pose_i, pose_j, calibration},
             {VariableType::pose2(), VariableType::pose2(),
              VariableType::vector(CalibrationIndex::kDim)},
             sensor_information),
      sensor_motion_(sensor_motion),
      cm_(std::cos(sensor_motion.theta)),
      sm_(std::sin(sensor_motion.theta)) {}

namespace {

// e = t2v(M⁻¹·(X_i⁻¹·X_j)) and its Jacobians with respect to X_i, X_j and M's translation,
// written for 3×3 and 3×2 column-major outputs (the relative-pose factor with Z = M).
struct MotionError {
  Eigen::Vector3d e;
  Eigen::Matrix3d Ji, Jj;
  Eigen::Matrix<double, 2, 2> Jt;  // d e_t / d t_M (e_θ does not depend on t_M)
};

MotionError motion_error(const double* a, const double* b, const SE2& M, double cz, double sz) {
  MotionError r;
  const double ci = std::cos(a[2]), si = std::sin(a[2]);
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double ax = ci * dx + si * dy, ay = -si * dx + ci * dy;
  const double ux = ax - M.x, uy = ay - M.y;
  r.e << cz * ux + sz * uy, -sz * ux + cz * uy, wrap_angle(b[2] - a[2] - M.theta);
  const double c = ci * cz - si * sz, s = si * cz + ci * sz;
  r.Ji << -c, -s, cz * ay - sz * ax, s, -c, -sz * ay - cz * ax, 0, 0, -1;
  r.Jj << c, s, 0, -s, c, 0, 0, 0, 1;
  r.Jt << -cz, -sz, sz, -cz;
  return r;
}

}  // namespace

Eigen::Vector3d SensorMotionFactor::robot_frame_error(const double* const* values) const {
  const SE2 M = sensor_to_robot_motion(sensor_motion_, cm_, sm_, values[2], nullptr);
  return motion_error(values[0], values[1], M, cm_, sm_).e;
}

void SensorMotionFactor::evaluate(const double* const* values, double* error,
                                  double* const* jacobians) const {
  const double* z = values[2];
  Eigen::Matrix<double, 2, 4> dt_dz;
  const SE2 M = sensor_to_robot_motion(sensor_motion_, cm_, sm_, z, dt_dz.data());
  const MotionError me = motion_error(values[0], values[1], M, cm_, sm_);
  // ẽ = G·e, G = diag(1/h, 1/h, 1)·Ad(T_vs)⁻¹: ẽ_t = (R_γᵀ e_t + e_θ·J·R_γᵀ·p) / h, ẽ_θ = e_θ.
  const double h = z[CalibrationIndex::kHeight], yaw = z[CalibrationIndex::kYaw];
  const Eigen::Vector2d p(z[CalibrationIndex::kX], z[CalibrationIndex::kY]);
  Eigen::Matrix2d Rt;  // R_γᵀ
  Rt << std::cos(yaw), std::sin(yaw), -std::sin(yaw), std::cos(yaw);
  Eigen::Matrix2d Jr;  // J = [[0, −1], [1, 0]], rotation by +90°
  Jr << 0, -1, 1, 0;
  const Eigen::Matrix2d Gt = Rt / h;
  const Eigen::Vector2d Rtp = Rt * p;
  const Eigen::Vector2d gth = Jr * Rtp / h;
  const Eigen::Vector2d et = me.e.head<2>();
  const double eth = me.e[2];
  const Eigen::Vector2d et_tilde = Gt * et + gth * eth;
  error[0] = et_tilde[0];
  error[1] = et_tilde[1];
  error[2] = eth;
  if (!jacobians) return;
  auto apply_G = [&](const Eigen::Matrix3d& Je, double* out) {
    Eigen::Map<Eigen::Matrix3d> J(out);
    J.topRows<2>() = Gt * Je.topRows<2>() + gth * Je.row(2);
    J.row(2) = Je.row(2);
  };
  if (jacobians[0]) apply_G(me.Ji, jacobians[0]);
  if (jacobians[1]) apply_G(me.Jj, jacobians[1]);
  if (double* out = jacobians[2]) {
    Eigen::Map<Eigen::Matrix<double, 3, 4>> J(out);
    // G·de/dz: e_t moves with t_M, e_θ not at all; plus dG/dz·e with e held.
    J.topRows<2>() = Gt * me.Jt * dt_dz;
    J.row(2).setZero();
    J.block<2, 2>(0, CalibrationIndex::kX) += eth / h * (Jr * Rt);
    J.col(CalibrationIndex::kHeight).head<2>() += -et_tilde / h;
    J.col(CalibrationIndex::kYaw).head<2>() += (-Jr * Rt * et + eth * Rtp) / h;
  }
}

NonholonomicFactor::NonholonomicFactor(VariableId calibration, const SE2& sensor_motion,
                                       double information, Form form)
    : Factor({calibration}, {VariableType::vector(CalibrationIndex::kDim)},
             Eigen::Matrix<double, 1, 1>(information)),
      sensor_motion_(sensor_motion) {
  // e = n·t(m_r); m_r's angle is the sensor's, so n is fixed by the measurement.
  const double half = 0.5 * sensor_motion.theta;
  nx_ = form == Form::Arc ? -std::sin(half) : 0.0;
  ny_ = form == Form::Arc ? std::cos(half) : 1.0;
}

void NonholonomicFactor::evaluate(const double* const* values, double* error,
                                  double* const* jacobians) const {
  Eigen::Matrix<double, 2, 4> dt_dz;
  const SE2 m = sensor_to_robot_motion(sensor_motion_, values[0],
                                       jacobians && jacobians[0] ? dt_dz.data() : nullptr);
  error[0] = nx_ * m.x + ny_ * m.y;
  if (jacobians && jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 1, 4>> J(jacobians[0]);
    J = nx_ * dt_dz.row(0) + ny_ * dt_dz.row(1);
  }
}

DirectionPriorFactor::DirectionPriorFactor(VariableId calibration, const SE2& sensor_motion,
                                           int direction, double information)
    : Factor({calibration}, {VariableType::vector(CalibrationIndex::kDim)},
             Eigen::Matrix<double, 1, 1>(information)),
      sensor_motion_(sensor_motion),
      direction_(direction) {
  if (direction < -1 || direction > 1)
    throw_invalid_argument("DirectionPriorFactor: the direction is -1, 0 or +1");
}

void DirectionPriorFactor::evaluate(const double* const* values, double* error,
                                    double* const* jacobians) const {
  Eigen::Matrix<double, 2, 4> dt_dz;
  const SE2 m = sensor_to_robot_motion(sensor_motion_, values[0], dt_dz.data());
  const bool active = direction_ == 0 || (direction_ > 0 ? m.x < 0.0 : m.x > 0.0);
  error[0] = active ? m.x : 0.0;
  if (jacobians && jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 1, 4>> J(jacobians[0]);
    if (active)
      J = dt_dz.row(0);
    else
      J.setZero();
  }
}

}  // namespace planarvo::graph
