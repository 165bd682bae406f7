#include "graph/factors.h"

#include <cmath>

#include "core/error.h"

namespace planarvo::graph {

RelativePoseFactor::RelativePoseFactor(VariableId from, VariableId to, const SE2& measurement,
                                       const Eigen::Matrix3d& information)
    : Factor({from, to}, {VariableType::pose2(), VariableType::pose2()}, information),
      measurement_(measurement),
      cz_(std::cos(measurement.theta)),
      sz_(std::sin(measurement.theta)) {}

void RelativePoseFactor::evaluate(const double* const* values, double* e,
                                  double* const* jacobians) const {
  const double* a = values[0];
  const double* b = values[1];
  const double ci = std::cos(a[2]), si = std::sin(a[2]);
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  // X_i⁻¹·X_j: translation R_iᵀ(t_j − t_i); then Z⁻¹·(…): R_Zᵀ(t_A − t_Z).
  const double ax = ci * dx + si * dy, ay = -si * dx + ci * dy;
  const double ux = ax - measurement_.x, uy = ay - measurement_.y;
  e[0] = cz_ * ux + sz_ * uy;
  e[1] = -sz_ * ux + cz_ * uy;
  e[2] = wrap_angle(b[2] - a[2] - measurement_.theta);
  if (!jacobians) return;
  // de_t/dt_j = R_Zᵀ R_iᵀ = R(−(θ_i + θ_Z)); de_t/dθ_i = R_Zᵀ · (dR_iᵀ/dθ)(t_j − t_i).
  const double c = ci * cz_ - si * sz_, s = si * cz_ + ci * sz_;
  if (double* J = jacobians[0]) {
    J[0] = -c, J[1] = s, J[2] = 0.0;
    J[3] = -s, J[4] = -c, J[5] = 0.0;
    J[6] = cz_ * ay - sz_ * ax, J[7] = -sz_ * ay - cz_ * ax, J[8] = -1.0;
  }
  if (double* J = jacobians[1]) {
    J[0] = c, J[1] = -s, J[2] = 0.0;
    J[3] = s, J[4] = c, J[5] = 0.0;
    J[6] = 0.0, J[7] = 0.0, J[8] = 1.0;
  }
}

PosePriorFactor::PosePriorFactor(VariableId pose, const SE2& prior,
                                 const Eigen::Matrix3d& information)
    : Factor({pose}, {VariableType::pose2()}, information),
      prior_(prior),
      cz_(std::cos(prior.theta)),
      sz_(std::sin(prior.theta)) {}

void PosePriorFactor::evaluate(const double* const* values, double* e,
                               double* const* jacobians) const {
  const double* x = values[0];
  const double ux = x[0] - prior_.x, uy = x[1] - prior_.y;
  e[0] = cz_ * ux + sz_ * uy;
  e[1] = -sz_ * ux + cz_ * uy;
  e[2] = wrap_angle(x[2] - prior_.theta);
  if (jacobians && jacobians[0]) {
    double* J = jacobians[0];
    J[0] = cz_, J[1] = -sz_, J[2] = 0.0;
    J[3] = sz_, J[4] = cz_, J[5] = 0.0;
    J[6] = 0.0, J[7] = 0.0, J[8] = 1.0;
  }
}

VectorPriorFactor::VectorPriorFactor(VariableId variable, const Eigen::VectorXd& prior,
                                     const Eigen::MatrixXd& information)
    : Factor({variable}, {VariableType::vector(static_cast<int>(prior.size()))}, information),
      prior_(prior) {
  if (information.rows() != prior.size())
    throw_invalid_argument("VectorPriorFactor: the information must be n × n for a prior of n");
}

void VectorPriorFactor::evaluate(const double* const* values, double* e,
                                 double* const* jacobians) const {
  const auto n = prior_.size();
  Eigen::Map<Eigen::VectorXd>(e, n) = Eigen::Map<const Eigen::VectorXd>(values[0], n) - prior_;
  if (jacobians && jacobians[0]) Eigen::Map<Eigen::MatrixXd>(jacobians[0], n, n).setIdentity();
}


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
