// SE(2) and extrinsics against independent computations: matrices, numeric round trips, and
// the worked example of shared/spec/conventions.md.
#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "core/error.h"
#include "core/extrinsics.h"
#include "core/motion.h"
#include "core/se2.h"

namespace planarvo {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(SE2, CompositionAndInverseMatchMatrices) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 100; ++i) {
    const SE2 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    EXPECT_LT(((a * b).matrix() - a.matrix() * b.matrix()).norm(), 1e-12);
    EXPECT_LT((a.inverse().matrix() - a.matrix().inverse()).norm(), 1e-12);
  }
}

TEST(SE2, ExpIsTheConstantVelocityArc) {
  // Integrate (v, omega) with tiny Euler steps and compare with exp.
  const Eigen::Vector3d xi(0.7, -0.1, 1.3);
  SE2 p;
  const int n = 200000;
  for (int i = 0; i < n; ++i) p = p * SE2(xi.x() / n, xi.y() / n, xi.z() / n);
  const SE2 e = SE2::exp(xi);
  EXPECT_NEAR(e.x, p.x, 1e-5);
  EXPECT_NEAR(e.y, p.y, 1e-5);
  EXPECT_NEAR(e.theta, p.theta, 1e-9);
  const Eigen::Vector3d back = e.log();
  EXPECT_LT((back - xi).norm(), 1e-12);
  EXPECT_LT((SE2::exp(Eigen::Vector3d(1e-9, 2e-9, 1e-8)).log() - Eigen::Vector3d(1e-9, 2e-9, 1e-8)).norm(), 1e-18);
}

TEST(Motion, CovarianceZeroMeansNotGiven) {
  Motion m{SE2(0.1, 0.2, 0.3)};
  EXPECT_FALSE(m.has_covariance());
  m.covariance(2, 0) = 1e-300;
  EXPECT_TRUE(m.has_covariance());
}

TEST(Motion, ComponentCovarianceIsTheRightPerturbationPropagated) {
  // J: the numeric derivative of value·exp(xi)'s (x, y, theta) by xi at 0; the components'
  // covariance is J Σ Jᵀ.
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 20; ++i) {
    Motion m{SE2(u(rng), u(rng), u(rng))};
    const Eigen::Matrix3d L = Eigen::Matrix3d::Random();
    m.covariance = L * L.transpose() + 0.1 * Eigen::Matrix3d::Identity();
    Eigen::Matrix3d J;
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(k);
      const SE2 p = m.value * SE2::exp(d), q = m.value * SE2::exp(-d);
      J.col(k) = Eigen::Vector3d(p.x - q.x, p.y - q.y, wrap_angle(p.theta - q.theta)) / (2 * h);
    }
    EXPECT_LT((component_covariance(m) - J * m.covariance * J.transpose()).norm(), 1e-8);
  }
}

TEST(Extrinsics, WorkedExampleOfConventions) {
  Extrinsics e{0.2441, -0.0185, 0.1787, 12.4 * kDeg, 17.6 * kDeg, -9.2 * kDeg};
  const Eigen::Vector3d n = e.plane_normal_camera();
  EXPECT_NEAR(n.x(), -0.2047, 5e-5);
  EXPECT_NEAR(n.y(), 0.3024, 5e-5);
  EXPECT_NEAR(n.z(), -0.9310, 5e-5);
  // The closed form of conventions.md.
  EXPECT_NEAR(n.x(), -std::sin(e.roll) * std::cos(e.pitch), 1e-12);
  EXPECT_NEAR(n.y(), std::sin(e.pitch), 1e-12);
  EXPECT_NEAR(n.z(), -std::cos(e.roll) * std::cos(e.pitch), 1e-12);
}

TEST(Extrinsics, ZeroAnglesLookStraightDownImageTopForward) {
  Extrinsics e{0, 0, 0.2, 0, 0, 0};
  const Eigen::Matrix3d R = e.R_vc();
  EXPECT_LT((R.col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-15);  // optical axis down
  EXPECT_LT((R.col(1) - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-15);  // image down = robot rear
  EXPECT_LT((R.col(0) - Eigen::Vector3d(0, -1, 0)).norm(), 1e-15);  // image right = robot right
}

TEST(Extrinsics, PositiveRollAndPitchTiltAsDocumented) {
  // roll > 0 tilts the optical axis towards the image's left, pitch > 0 towards its bottom.
  const Eigen::Vector3d axis_roll = Extrinsics{0, 0, 1, 0.1, 0, 0}.R_vc().col(2);
  EXPECT_GT(axis_roll.y(), 0.0);  // robot's left = image left at yaw 0
  const Eigen::Vector3d axis_pitch = Extrinsics{0, 0, 1, 0, 0.1, 0}.R_vc().col(2);
  EXPECT_LT(axis_pitch.x(), 0.0);  // robot's rear = image bottom
}

TEST(Extrinsics, MatrixRoundTrip) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> a(-1.4, 1.4), t(-1, 1);
  for (int i = 0; i < 200; ++i) {
    Extrinsics e{t(rng), t(rng), t(rng), a(rng), a(rng), 2 * a(rng)};
    const Extrinsics r = Extrinsics::from_matrix(e.T_vc());
    EXPECT_NEAR(r.roll, e.roll, 1e-9);
    EXPECT_NEAR(r.pitch, e.pitch, 1e-9);
    EXPECT_NEAR(r.yaw, e.yaw, 1e-9);
    EXPECT_NEAR(r.z, e.z, 1e-15);
  }
  Eigen::Matrix4d bad = Eigen::Matrix4d::Identity();
  bad(0, 0) = 2;
  EXPECT_THROW(Extrinsics::from_matrix(bad), Error);
}

TEST(GroundHomography, MapsProjectedGroundPoints) {
  // Project ground points into two camera poses directly and compare with the homography.
  Extrinsics e{0.2441, -0.0185, 0.1787, 12.4 * kDeg, 17.6 * kDeg, -9.2 * kDeg};
  Eigen::Matrix3d K;
  K << 400, 0, 320, 0, 410, 240, 0, 0, 1;
  const SE2 motion(0.012, -0.004, 0.03);  // live robot pose in the reference robot frame
  const Eigen::Matrix3d H = ground_homography(K, e, motion.matrix3d());
  const Eigen::Matrix4d T_cv = e.T_vc().inverse();
  const Eigen::Matrix4d T_live_cv = T_cv * motion.matrix3d().inverse();  // world(=ref robot) -> live cam
  for (double gx : {0.15, 0.25, 0.35})
    for (double gy : {-0.1, 0.0, 0.1}) {
      const Eigen::Vector4d X(gx, gy, 0, 1);
      const Eigen::Vector3d xr = K * (T_cv * X).head<3>();
      const Eigen::Vector3d xl = K * (T_live_cv * X).head<3>();
      const Eigen::Vector3d m = H * xr;
      EXPECT_NEAR(m.x() / m.z(), xl.x() / xl.z(), 1e-9);
      EXPECT_NEAR(m.y() / m.z(), xl.y() / xl.z(), 1e-9);
    }
}

}  // namespace
}  // namespace planarvo
