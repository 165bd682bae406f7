// The composition of the two calibration stages (calib/extrinsics_estimate.h) against plain matrix
// products: the camera's ground frame T_vs = (x, y, yaw) times the tilted camera T_sc at height z
// is the camera's T_vc, and the covariance blocks land where the six parameters are.
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "calib/extrinsics_estimate.h"

namespace planarvo::calib {
namespace {

TEST(ComposeExtrinsics, GroundFrameTimesTiltedCameraIsTheCamerasPose) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const double x = 0.3 * u(rng), y = 0.2 * u(rng), z = 0.2 + 0.1 * u(rng), yaw = M_PI * u(rng);
    const double roll = 0.5 * u(rng), pitch = 0.5 * u(rng);
    graph::CalibrationResult g;
    g.value = {x, y, z, yaw};
    g.estimated = {true, true, true, true};
    g.observable = {true, true, true, true};
    Eigen::Matrix4d gc = Eigen::Matrix4d::Identity();
    gc(0, 3) = gc(3, 0) = 0.1;  // x-yaw correlation
    g.covariance = gc * 1e-6;
    const Eigen::Matrix2d rp = Eigen::Vector2d(4e-8, 9e-8).asDiagonal();
    const ExtrinsicsEstimate e = compose_extrinsics(roll, pitch, rp, true, g);

    // T_vs: the ground frame; T_sc: the camera tilted by roll and pitch, z above it.
    Eigen::Matrix4d T_vs = Eigen::Matrix4d::Identity();
    T_vs.topLeftCorner<3, 3>() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_vs(0, 3) = x;
    T_vs(1, 3) = y;
    const Extrinsics sc{0, 0, z, roll, pitch, 0};
    const Eigen::Matrix4d T_vc = T_vs * sc.T_vc();
    EXPECT_LT((e.value.T_vc() - T_vc).norm(), 1e-12) << trial;

    EXPECT_DOUBLE_EQ(e.covariance(0, 5), g.covariance(0, 3));  // x-yaw
    EXPECT_DOUBLE_EQ(e.covariance(2, 2), g.covariance(2, 2));  // scale is z
    EXPECT_DOUBLE_EQ(e.covariance(4, 4), rp(1, 1));            // pitch
    EXPECT_EQ(e.covariance(3, 0), 0.0);                        // stages independent
    for (bool b : e.estimated) EXPECT_TRUE(b);
  }
}

TEST(ComposeExtrinsics, GivenParametersAreMarkedAndHaveNoCovariance) {
  graph::CalibrationResult g;  // the nonholonomic method with the height given, no labels
  g.value = {0.2, 0.0, 0.15, 0.1};
  g.estimated = {true, false, false, true};
  g.observable = {true, false, false, true};
  g.covariance = Eigen::Matrix4d::Identity() * 1e-6;
  const ExtrinsicsEstimate e = compose_extrinsics(0.1, 0.2, Eigen::Matrix2d::Zero(), false, g);
  EXPECT_FALSE(e.estimated[1]);
  EXPECT_FALSE(e.estimated[2]);
  EXPECT_FALSE(e.estimated[3]);
  EXPECT_FALSE(e.estimated[4]);
  EXPECT_TRUE(e.estimated[0]);
  EXPECT_EQ(e.covariance.row(1).norm(), 0.0);
  EXPECT_EQ(e.covariance.row(2).norm(), 0.0);
  EXPECT_EQ((e.covariance.block<2, 6>(3, 0).norm()), 0.0);
  EXPECT_DOUBLE_EQ(e.value.z, 0.15);
}

// With the tilt's share (calib/tilt_propagation.h): the graph's parameters are the tilt-free
// estimate g0 plus J (roll, pitch) error, so the joint covariance of (g, roll, pitch) is
// A blockdiag(G, C) A^T with A = [[I, J], [0, I]], put where the six parameters are. A parameter
// the graph did not estimate (y here) stays without covariance.
TEST(ComposeExtrinsics, TheTiltsShareIsTheLinearMapsCovariance) {
  graph::CalibrationResult g;
  g.value = {0.2, 0.0, 0.15, 0.1};
  g.estimated = {true, false, true, true};
  g.observable = {true, false, true, true};
  g.covariance = Eigen::Vector4d(4e-6, 0.0, 2e-6, 1e-6).asDiagonal();
  g.covariance(0, 3) = g.covariance(3, 0) = 5e-7;
  Eigen::Matrix2d C;
  C << 4e-8, 1e-8, 1e-8, 9e-8;
  Eigen::Matrix<double, 4, 2> J;
  J << 0.3, -0.1, 7.0, 2.0, 0.05, 0.2, -0.8, 0.6;  // the y row is not used: y is not estimated
  const ExtrinsicsEstimate e = compose_extrinsics(0.1, 0.2, C, true, g, &J);

  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Identity();
  A.topRightCorner<4, 2>() = J;
  Eigen::Matrix<double, 6, 6> B = Eigen::Matrix<double, 6, 6>::Zero();
  B.topLeftCorner<4, 4>() = g.covariance;
  B.bottomRightCorner<2, 2>() = C;
  const Eigen::Matrix<double, 6, 6> joint = A * B * A.transpose();  // order x y scale yaw roll pitch
  const int at[6] = {0, 1, 2, 5, 3, 4};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const bool zero = at[i] == 1 || at[j] == 1;
      EXPECT_NEAR(e.covariance(at[i], at[j]), zero ? 0.0 : joint(i, j), 1e-18) << i << " " << j;
    }
}

}  // namespace
}  // namespace planarvo::calib
