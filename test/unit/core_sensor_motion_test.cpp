// core/sensor_motion.h against independent computations: the motion by 3x3 homogeneous matrices,
// its covariance by numeric differentiation of the map from robot to sensor perturbations; and
// the C API's copy of it.
#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/error.h"
#include "core/sensor_motion.h"
#include "planarvo/planarvo.h"

namespace planarvo {
namespace {

Eigen::Matrix3d homogeneous(double x, double y, double theta) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(theta).toRotationMatrix();
  m(0, 2) = x;
  m(1, 2) = y;
  return m;
}

// exp of se(2) by the matrix exponential of its 3x3 generator (Eigen's Pade approximant would need
// unsupported/; a truncated series to 30 terms is exact to rounding for |xi| < 1).
Eigen::Matrix3d exp_matrix(const Eigen::Vector3d& xi) {
  Eigen::Matrix3d g = Eigen::Matrix3d::Zero();
  g(0, 1) = -xi(2);
  g(1, 0) = xi(2);
  g(0, 2) = xi(0);
  g(1, 2) = xi(1);
  Eigen::Matrix3d sum = Eigen::Matrix3d::Identity(), term = Eigen::Matrix3d::Identity();
  for (int k = 1; k < 30; ++k) {
    term = term * g / k;
    sum += term;
  }
  return sum;
}

TEST(CoreSensorMotion, IsTheConjugatedMotionInHeightUnitsWithItsCovarianceCarried) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Extrinsics e;
    e.x = 0.5 * u(rng);
    e.y = 0.5 * u(rng);
    e.z = 0.1 + std::abs(u(rng));
    e.roll = 0.2 * u(rng);
    e.pitch = 0.3 * u(rng);
    e.yaw = 3.0 * u(rng);
    Motion m;
    m.value = SE2(0.05 * u(rng), 0.01 * u(rng), 0.1 * u(rng));
    Eigen::Matrix3d a = Eigen::Matrix3d::Random();
    m.covariance = 1e-6 * (a * a.transpose() + Eigen::Matrix3d::Identity());

    const Motion s = sensor_motion(e, m);
    // The motion: T^-1 M T by matrices, the translation divided by the height.
    const Eigen::Matrix3d T = homogeneous(e.x, e.y, e.yaw);
    const Eigen::Matrix3d expected = T.inverse() * homogeneous(m.value.x, m.value.y, m.value.theta) * T;
    EXPECT_NEAR(s.value.x, expected(0, 2) / e.z, 1e-12);
    EXPECT_NEAR(s.value.y, expected(1, 2) / e.z, 1e-12);
    EXPECT_NEAR(s.value.theta, std::atan2(expected(1, 0), expected(0, 0)), 1e-12);

    // The covariance: J = d(xi_s)/d(xi) numerically, where M exp(xi) maps to
    // S(T^-1 M exp(xi) T) = S(M_s) exp(xi_s).
    const Eigen::Matrix3d Ms = homogeneous(s.value.x, s.value.y, s.value.theta);
    Eigen::Matrix3d J;
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d xi = Eigen::Vector3d::Zero();
      xi(k) = h;
      Eigen::Matrix3d p = T.inverse() * homogeneous(m.value.x, m.value.y, m.value.theta) * exp_matrix(xi) * T;
      p(0, 2) /= e.z;
      p(1, 2) /= e.z;
      const Eigen::Matrix3d d = Ms.inverse() * p;  // exp(xi_s), xi_s small
      J.col(k) = Eigen::Vector3d(d(0, 2), d(1, 2), std::atan2(d(1, 0), d(0, 0))) / h;
    }
    const Eigen::Matrix3d expected_cov = J * m.covariance * J.transpose();
    EXPECT_LT((s.covariance - expected_cov).cwiseAbs().maxCoeff(), 1e-6 * expected_cov.cwiseAbs().maxCoeff() + 1e-15)
        << "trial " << trial;

    // The C API's function is the same.
    const planarvo_extrinsics ce{e.x, e.y, e.z, e.roll, e.pitch, e.yaw};
    const planarvo_se2 cm{m.value.x, m.value.y, m.value.theta};
    double cov[9], out_cov[9];
    for (int k = 0; k < 9; ++k) cov[k] = m.covariance(k / 3, k % 3);
    planarvo_se2 cs{};
    ASSERT_EQ(planarvo_sensor_motion(&ce, &cm, cov, &cs, out_cov), PLANARVO_OK) << planarvo_last_error();
    EXPECT_EQ(cs.x, s.value.x);
    EXPECT_EQ(cs.theta, s.value.theta);
    EXPECT_EQ(out_cov[1], s.covariance(0, 1));
  }
  // The sensor frame itself (x = y = 0, z = 1, yaw = 0): motions unchanged.
  Motion m;
  m.value = SE2(0.03, -0.001, 0.02);
  const Motion same = sensor_motion(Extrinsics{0, 0, 1, 0.2, 0.3, 0}, m);
  EXPECT_NEAR(same.value.x, m.value.x, 1e-15);
  EXPECT_NEAR(same.value.y, m.value.y, 1e-15);
  EXPECT_THROW(sensor_motion(Extrinsics{0, 0, 0, 0, 0, 0}, m), Error);
}

}  // namespace
}  // namespace planarvo
