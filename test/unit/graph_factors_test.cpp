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
#include "graph/factors.h"
#include "graph/robust_kernel.h"

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
