// Factors and robust kernels against independent computations: every analytic Jacobian against
// central differences at random states, errors against SE(2) matrix algebra, kernels against
// their definitions and numeric derivatives.
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/error.h"
#include "core/se2.h"
#include "graph/posegraph/factors.h"
#include "graph/calibration/factors.h"
#include "graph/solver/robust_kernel.h"

namespace planarvo::graph {
namespace {

// Central differences of e over each stored coordinate of each variable. Step 1e-5: the
// truncation error is h²/6·|e'''| ≲ 1e-10 for errors of size O(10) with O(1) curvature, and the
// rounding error ε·|e|/h ≈ 1e-10; the tolerance below (1e-7, relative to the Jacobian's scale)
// leaves three orders of margin yet catches any wrong term (those are O(1)). Differences are
// wrapped so that an angle error near ±π does not jump by 2π.
std::vector<Eigen::MatrixXd> numeric_jacobians(const Factor& f,
                                               std::vector<std::vector<double>> values) {
  const int m = f.residual_dim();
  std::vector<Eigen::MatrixXd> J;
  const double h = 1e-5;
  for (size_t k = 0; k < values.size(); ++k) {
    Eigen::MatrixXd Jk(m, static_cast<int>(values[k].size()));
    for (size_t p = 0; p < values[k].size(); ++p) {
      auto eval = [&](double d) {
        std::vector<std::vector<double>> v = values;
        v[k][p] += d;
        std::vector<const double*> ptrs;
        for (auto& x : v) ptrs.push_back(x.data());
        Eigen::VectorXd e(m);
        f.evaluate(ptrs.data(), e.data(), nullptr);
        return e;
      };
      const Eigen::VectorXd diff = eval(h) - eval(-h);
      for (int i = 0; i < m; ++i) Jk(i, static_cast<int>(p)) = wrap_angle(diff[i]) / (2 * h);
    }
    J.push_back(Jk);
  }
  return J;
}

std::vector<Eigen::MatrixXd> analytic_jacobians(const Factor& f,
                                                std::vector<std::vector<double>> values,
                                                Eigen::VectorXd* error = nullptr) {
  const int m = f.residual_dim();
  std::vector<Eigen::MatrixXd> J;
  std::vector<double*> jptrs;
  std::vector<const double*> ptrs;
  for (auto& x : values) {
    J.emplace_back(m, static_cast<int>(x.size()));
    ptrs.push_back(x.data());
  }
  for (auto& j : J) jptrs.push_back(j.data());
  Eigen::VectorXd e(m);
  f.evaluate(ptrs.data(), e.data(), jptrs.data());
  if (error) *error = e;
  return J;
}

void expect_jacobians_match(const Factor& f, const std::vector<std::vector<double>>& values) {
  const auto A = analytic_jacobians(f, values);
  const auto N = numeric_jacobians(f, values);
  for (size_t k = 0; k < A.size(); ++k) {
    const double scale = std::max(1.0, N[k].cwiseAbs().maxCoeff());
    EXPECT_LT((A[k] - N[k]).cwiseAbs().maxCoeff(), 1e-7 * scale)
        << "variable " << k << "\nanalytic\n" << A[k] << "\nnumeric\n" << N[k];
  }
}

Eigen::Matrix3d random_information(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i) = u(rng);
  return A * A.transpose() + Eigen::Matrix3d::Identity();
}

SE2 random_pose(std::mt19937& rng, double extent = 10.0) {
  std::uniform_real_distribution<double> u(-1, 1);
  return {extent * u(rng), extent * u(rng), M_PI * u(rng)};
}

std::vector<double> coords(const SE2& p) { return {p.x, p.y, p.theta}; }

double angle_distance(double a, double b) { return std::abs(wrap_angle(a - b)); }

TEST(GraphFactors, RelativePoseErrorIsG2oConvention) {
  // e = t2v(Z⁻¹ · (X_i⁻¹ · X_j)) computed with 3×3 matrices.
  std::mt19937 rng(7);
  for (int t = 0; t < 50; ++t) {
    const SE2 xi = random_pose(rng), xj = random_pose(rng), z = random_pose(rng, 2.0);
    RelativePoseFactor f(0, 1, z, random_information(rng));
    Eigen::VectorXd e;
    analytic_jacobians(f, {coords(xi), coords(xj)}, &e);
    const Eigen::Matrix3d E = z.matrix().inverse() * xi.matrix().inverse() * xj.matrix();
    EXPECT_NEAR(e[0], E(0, 2), 1e-10);
    EXPECT_NEAR(e[1], E(1, 2), 1e-10);
    EXPECT_NEAR(e[2], std::atan2(E(1, 0), E(0, 0)), 1e-10);
  }
}

TEST(GraphFactors, RelativePoseJacobiansMatchNumeric) {
  std::mt19937 rng(11);
  for (int t = 0; t < 100; ++t) {
    RelativePoseFactor f(0, 1, random_pose(rng, 2.0), random_information(rng));
    expect_jacobians_match(f, {coords(random_pose(rng)), coords(random_pose(rng))});
  }
}

TEST(GraphFactors, PosePriorErrorAndJacobian) {
  std::mt19937 rng(13);
  for (int t = 0; t < 100; ++t) {
    const SE2 prior = random_pose(rng), x = random_pose(rng);
    PosePriorFactor f(0, prior, random_information(rng));
    Eigen::VectorXd e;
    analytic_jacobians(f, {coords(x)}, &e);
    const Eigen::Matrix3d E = prior.matrix().inverse() * x.matrix();
    EXPECT_NEAR(e[0], E(0, 2), 1e-10);
    EXPECT_NEAR(e[1], E(1, 2), 1e-10);
    EXPECT_NEAR(e[2], std::atan2(E(1, 0), E(0, 0)), 1e-10);
    expect_jacobians_match(f, {coords(x)});
  }
}

TEST(GraphFactors, VectorPriorErrorAndJacobian) {
  Eigen::VectorXd mu(4);
  mu << 1, -2, 0.5, 3;
  VectorPriorFactor f(0, mu, Eigen::Vector4d(1, 2, 3, 4).asDiagonal().toDenseMatrix());
  Eigen::VectorXd e;
  const auto J = analytic_jacobians(f, {{0.5, 0.5, 0.5, 0.5}}, &e);
  EXPECT_LT((e - (Eigen::Vector4d(0.5, 0.5, 0.5, 0.5) - mu)).norm(), 1e-15);
  expect_jacobians_match(f, {{0.5, 0.5, 0.5, 0.5}});
  EXPECT_THROW(VectorPriorFactor(0, mu, Eigen::Matrix3d::Identity()), Error);
}

TEST(GraphFactors, InformationMustBeSymmetricPositiveDefinite) {
  Eigen::Matrix3d bad = Eigen::Matrix3d::Identity();
  bad(2, 2) = -1;
  EXPECT_THROW(RelativePoseFactor(0, 1, SE2(), bad), Error);
  Eigen::Matrix3d asym = Eigen::Matrix3d::Identity();
  asym(0, 1) = 0.5;
  EXPECT_THROW(RelativePoseFactor(0, 1, SE2(), asym), Error);
  std::mt19937 rng(3);
  const Eigen::Matrix3d info = random_information(rng);
  RelativePoseFactor ok(0, 1, SE2(), info);
  const Eigen::MatrixXd L = ok.sqrt_information();
  EXPECT_LT((L.transpose() * L - info).norm(), 1e-12);
  EXPECT_EQ(L(1, 0), 0.0);  // upper triangular
}

// ---- calibration factors --------------------------------------------------------------------

// z = (x, y, height, yaw) with a realistic spread: height in [0.1, 2].
std::vector<double> random_calibration(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  return {0.5 * u(rng), 0.5 * u(rng), 1.05 + 0.95 * u(rng), M_PI * u(rng)};
}

// T·S_h(m)·T⁻¹ with 3×3 matrices.
Eigen::Matrix3d mapped_motion(const SE2& m, const std::vector<double>& z) {
  const SE2 T(z[0], z[1], z[3]);
  const SE2 scaled(z[2] * m.x, z[2] * m.y, m.theta);
  return T.matrix() * scaled.matrix() * T.matrix().inverse();
}

TEST(GraphCalibrationFactors, SensorToRobotMotionIsTheConjugation) {
  std::mt19937 rng(17);
  for (int t = 0; t < 100; ++t) {
    const SE2 m = random_pose(rng, 1.0);
    const std::vector<double> z = random_calibration(rng);
    Eigen::Matrix<double, 2, 4> J;
    const SE2 r = sensor_to_robot_motion(m, z.data(), J.data());
    const Eigen::Matrix3d ref = mapped_motion(m, z);
    EXPECT_NEAR(r.x, ref(0, 2), 1e-12);
    EXPECT_NEAR(r.y, ref(1, 2), 1e-12);
    EXPECT_NEAR(angle_distance(r.theta, std::atan2(ref(1, 0), ref(0, 0))), 0.0, 1e-12);
    for (int k = 0; k < 4; ++k) {
      std::vector<double> zp = z, zm = z;
      zp[static_cast<size_t>(k)] += 1e-6;
      zm[static_cast<size_t>(k)] -= 1e-6;
      const SE2 a = sensor_to_robot_motion(m, zp.data()), b = sensor_to_robot_motion(m, zm.data());
      EXPECT_NEAR(J(0, k), (a.x - b.x) / 2e-6, 1e-7);
      EXPECT_NEAR(J(1, k), (a.y - b.y) / 2e-6, 1e-7);
    }
  }
}

TEST(GraphCalibrationFactors, SensorFactorIsEq26WithProjectedInformation) {
  std::mt19937 rng(19);
  for (int t = 0; t < 50; ++t) {
    const SE2 xi = random_pose(rng), xj = random_pose(rng), m = random_pose(rng, 1.0);
    const std::vector<double> z = random_calibration(rng);
    const Eigen::Matrix3d info_s = random_information(rng);
    SensorMotionFactor f(0, 1, 2, m, info_s);
    const std::vector<double> a = coords(xi), b = coords(xj);
    const double* v[3] = {a.data(), b.data(), z.data()};
    // The robot-frame error of eq. 26, e = t2v(m_r⁻¹·(X_i⁻¹·X_j)), with matrices.
    const Eigen::Matrix3d E = mapped_motion(m, z).inverse() * xi.matrix().inverse() * xj.matrix();
    const Eigen::Vector3d e = f.robot_frame_error(v);
    EXPECT_NEAR(e[0], E(0, 2), 1e-10);
    EXPECT_NEAR(e[1], E(1, 2), 1e-10);
    EXPECT_NEAR(e[2], std::atan2(E(1, 0), E(0, 0)), 1e-10);
    // Its cost under Ω̂ = (Ad·H)⁻ᵀ Ω_s (Ad·H)⁻¹, Ad the adjoint of T_vs found numerically from
    // T·exp(ξ)·T⁻¹ = exp(Ad·ξ), H = diag(h, h, 1).
    const SE2 T(z[0], z[1], z[3]);
    Eigen::Matrix3d Ad;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[k] = 1e-6;
      Ad.col(k) = ((T * SE2::exp(d) * T.inverse()).log() - (T * SE2::exp(-d) * T.inverse()).log()) / 2e-6;
    }
    const Eigen::Matrix3d AH = Ad * Eigen::Vector3d(z[2], z[2], 1).asDiagonal();
    const Eigen::Matrix3d info_r = AH.inverse().transpose() * info_s * AH.inverse();
    Eigen::Vector3d et;
    f.evaluate(v, et.data(), nullptr);
    EXPECT_NEAR(et.dot(info_s * et), e.dot(info_r * e), 1e-6 * std::max(1.0, e.dot(info_r * e)));
    expect_jacobians_match(f, {a, b, z});
  }
}

TEST(GraphCalibrationFactors, SensorFactorErrorIsTheSensorNoise) {
  // At a consistent state, perturbing the measured sensor motion by exp(ξ) gives ẽ ≈ −ξ: the
  // factor's error is in the sensor's units, where Ω_s applies.
  std::mt19937 rng(23);
  for (int t = 0; t < 20; ++t) {
    const std::vector<double> z = random_calibration(rng);
    const SE2 m = random_pose(rng, 1.0), xi = random_pose(rng);
    const Eigen::Matrix3d mr = mapped_motion(m, z);
    const SE2 xj = xi * SE2(mr(0, 2), mr(1, 2), std::atan2(mr(1, 0), mr(0, 0)));
    const Eigen::Vector3d noise(1e-6, -2e-6, 1.5e-6);
    SensorMotionFactor f(0, 1, 2, m * SE2::exp(noise), Eigen::Matrix3d::Identity());
    const std::vector<double> a = coords(xi), b = coords(xj);
    const double* v[3] = {a.data(), b.data(), z.data()};
    Eigen::Vector3d e;
    f.evaluate(v, e.data(), nullptr);
    EXPECT_LT((e + noise).norm(), 1e-9 + 1e-4 * noise.norm()) << e.transpose();
  }
}

TEST(GraphCalibrationFactors, NonholonomicFactorValuesAndJacobians) {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int t = 0; t < 50; ++t) {
    const std::vector<double> z = random_calibration(rng);
    const SE2 T(z[0], z[1], z[3]);
    // A differential-drive arc (v, 0, ω) seen by the sensor: m_s = S_{1/h}(T⁻¹·m_r·T).
    const SE2 arc = SE2::exp(Eigen::Vector3d(u(rng), 0.0, u(rng)));
    const SE2 ms_h = T.inverse() * arc * T;
    const SE2 ms(ms_h.x / z[2], ms_h.y / z[2], ms_h.theta);
    NonholonomicFactor arc_f(0, ms, 1.0), vel_f(0, ms, 1.0, NonholonomicFactor::Form::Velocity);
    double e = 1.0;
    std::vector<double> zz = z;
    const double* v[1] = {zz.data()};
    arc_f.evaluate(v, &e, nullptr);
    EXPECT_NEAR(e, 0.0, 1e-12);  // the true z explains an arc
    // ... whatever y is: the nonholonomic constraint cannot see it.
    zz[1] += 0.3;
    arc_f.evaluate(v, &e, nullptr);
    EXPECT_NEAR(e, 0.0, 1e-12);
    // Off the truth: the formula of conventions.md, and the lateral motion for the velocity form.
    zz = random_calibration(rng);
    v[0] = zz.data();
    const Eigen::Matrix3d M = mapped_motion(ms, zz);
    const double th = std::atan2(M(1, 0), M(0, 0));
    arc_f.evaluate(v, &e, nullptr);
    EXPECT_NEAR(e, M(1, 2) * std::cos(th / 2) - M(0, 2) * std::sin(th / 2), 1e-12);
    vel_f.evaluate(v, &e, nullptr);
    EXPECT_NEAR(e, M(1, 2), 1e-12);
    expect_jacobians_match(arc_f, {zz});
    expect_jacobians_match(vel_f, {zz});
  }
}

TEST(GraphCalibrationFactors, DirectionPriorPenalisesOnlyTheWrongDirection) {
  std::vector<double> z = {0.2, -0.1, 1.0, 0.0};
  const double* v[1] = {z.data()};
  const SE2 forward(0.5, 0.0, 0.1), backward(-0.5, 0.0, -0.1);
  double e;
  DirectionPriorFactor(0, forward, +1, 1.0).evaluate(v, &e, nullptr);
  EXPECT_EQ(e, 0.0);
  DirectionPriorFactor(0, forward, -1, 1.0).evaluate(v, &e, nullptr);
  EXPECT_NEAR(e, sensor_to_robot_motion(forward, z.data()).x, 1e-15);
  EXPECT_GT(e, 0.0);
  DirectionPriorFactor(0, backward, -1, 1.0).evaluate(v, &e, nullptr);
  EXPECT_EQ(e, 0.0);
  DirectionPriorFactor(0, backward, +1, 1.0).evaluate(v, &e, nullptr);
  EXPECT_LT(e, 0.0);
  DirectionPriorFactor(0, forward, 0, 1.0).evaluate(v, &e, nullptr);
  EXPECT_NEAR(e, sensor_to_robot_motion(forward, z.data()).x, 1e-15);
  EXPECT_THROW(DirectionPriorFactor(0, forward, 2, 1.0), Error);
  // Jacobians where the prior is active (away from the kink at m_r,x = 0).
  std::mt19937 rng(31);
  for (int t = 0; t < 30; ++t) {
    const std::vector<double> zz = random_calibration(rng);
    const SE2 m = random_pose(rng, 1.0);
    if (std::abs(sensor_to_robot_motion(m, zz.data()).x) < 1e-3) continue;
    for (int d : {-1, 0, 1}) expect_jacobians_match(DirectionPriorFactor(0, m, d, 2.0), {zz});
  }
}

// ---- robust kernels -------------------------------------------------------------------------

void expect_kernel_derivatives(const RobustKernel& k, double s) {
  double r[3], rp[3], rm[3];
  const double h = 1e-6 * std::max(1.0, s);
  k.evaluate(s, r);
  k.evaluate(s + h, rp);
  k.evaluate(s - h, rm);
  EXPECT_NEAR(r[1], (rp[0] - rm[0]) / (2 * h), 1e-6 * std::max(1.0, std::abs(r[1]))) << k.name() << " s=" << s;
  EXPECT_NEAR(r[2], (rp[1] - rm[1]) / (2 * h), 1e-5 * std::max(1.0, std::abs(r[2]))) << k.name() << " s=" << s;
}

TEST(GraphRobustKernels, ValuesMatchDefinitions) {
  const double d = 1.5;
  HuberKernel huber(d);
  CauchyKernel cauchy(d);
  TukeyKernel tukey(d);
  double r[3];
  for (double s : {0.0, 0.3, 1.0, 2.25, 3.0, 10.0, 1e4}) {
    const double e = std::sqrt(s);
    huber.evaluate(s, r);
    EXPECT_DOUBLE_EQ(r[0], e <= d ? s : 2 * d * e - d * d);
    EXPECT_DOUBLE_EQ(r[1], e <= d ? 1.0 : d / e);
    cauchy.evaluate(s, r);
    EXPECT_NEAR(r[0], d * d * std::log(1 + s / (d * d)), 1e-12 * std::max(1.0, r[0]));
    EXPECT_NEAR(r[1], 1.0 / (1 + s / (d * d)), 1e-15);
    tukey.evaluate(s, r);
    const double a = 1 - s / (d * d);
    EXPECT_NEAR(r[0], e <= d ? d * d / 3 * (1 - a * a * a) : d * d / 3, 1e-12);
    EXPECT_NEAR(r[1], e <= d ? a * a : 0.0, 1e-15);
  }
  // All three are χ²-like near zero: ρ(s) ≈ s, ρ'(0) = 1.
  for (const RobustKernel* k : std::initializer_list<const RobustKernel*>{&huber, &cauchy, &tukey}) {
    k->evaluate(1e-8, r);
    EXPECT_NEAR(r[0], 1e-8, 1e-15);
    EXPECT_NEAR(r[1], 1.0, 1e-8);
  }
  EXPECT_THROW(HuberKernel(0.0), Error);
  EXPECT_THROW(CauchyKernel(-1.0), Error);
}

TEST(GraphRobustKernels, DerivativesMatchNumeric) {
  HuberKernel huber(1.3);
  CauchyKernel cauchy(0.7);
  TukeyKernel tukey(2.0);
  for (double s : {0.01, 0.5, 1.0, 1.5, 2.0, 3.5, 7.0, 50.0}) {
    if (std::abs(s - 1.69) > 1e-3) expect_kernel_derivatives(huber, s);
    expect_kernel_derivatives(cauchy, s);
    if (std::abs(s - 4.0) > 1e-3) expect_kernel_derivatives(tukey, s);
  }
}

}  // namespace
}  // namespace planarvo::graph
