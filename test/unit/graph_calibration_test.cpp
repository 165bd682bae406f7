// The paper's calibration graphs (sec. 5.2) on simulated motions with known extrinsics:
// calibration against wheel odometry recovers z within its own marginal covariance, the
// nonholonomic graph cannot see y and the observability report says so by name, and direction
// labels of 0 (turning in place) make y observable.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "graph/solver/covariance.h"
#include "graph/calibration/factors.h"
#include "graph/calibration/pair_residuals.h"
#include "graph/posegraph/factors.h"
#include "graph/solver/solver.h"

namespace planarvo::graph {
namespace {

using CI = CalibrationIndex;

// The paper's camera configuration 1 (conventions.md): x, y, height, yaw.
const Eigen::Vector4d kTruth(0.2441, -0.0185, 0.1787, -9.2 * M_PI / 180);

struct Interval {
  SE2 robot;   // true robot motion
  SE2 odometry;
  SE2 sensor;  // measured sensor motion, up to the height's scale
  int direction;
};

// Constant-curvature intervals, forwards, backwards and turning in place; the sensor motion is
// S_{1/h}(T⁻¹·m_r·T), both measurements perturbed on the right by exp(noise).
std::vector<Interval> simulate(int n, const Eigen::Vector4d& z, double odo_noise, double sensor_noise,
                               unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> g(0, 1);
  const SE2 T(z[CI::kX], z[CI::kY], z[CI::kYaw]);
  std::vector<Interval> out;
  for (int k = 0; k < n; ++k) {
    const int kind = k % 5;  // 0: turn in place, 1, 2: forwards, 3, 4: backwards
    const double v = kind == 0 ? 0.0 : (kind <= 2 ? 1 : -1) * (0.1 + 0.3 * std::abs(u(rng)));
    const double w = 0.8 * u(rng);
    Interval it;
    it.robot = SE2::exp(Eigen::Vector3d(v, 0.0, w));
    it.direction = v > 0 ? 1 : (v < 0 ? -1 : 0);
    it.odometry = it.robot * SE2::exp(odo_noise * Eigen::Vector3d(g(rng), g(rng), g(rng)));
    const SE2 s = T.inverse() * it.robot * T;
    it.sensor = SE2(s.x / z[CI::kHeight], s.y / z[CI::kHeight], s.theta) *
                SE2::exp(sensor_noise * Eigen::Vector3d(g(rng), g(rng), g(rng)));
    out.push_back(it);
  }
  return out;
}

TEST(GraphCalibration, OdometryCalibrationRecoversTheExtrinsics) {
  const double odo_sigma = 0.002, sensor_sigma = 0.002;
  const auto intervals = simulate(300, kTruth, odo_sigma, sensor_sigma, 1);
  FactorGraph g;
  const VariableId z = g.add_vector(Eigen::Vector4d(0.0, 0.0, 1.0, 0.0), "z", calibration_parameter_names());
  std::vector<VariableId> r = {g.add_pose(SE2())};
  g.set_fixed(r[0]);
  const Eigen::Matrix3d odo_info = Eigen::Matrix3d::Identity() / (odo_sigma * odo_sigma);
  const Eigen::Matrix3d sensor_info = Eigen::Matrix3d::Identity() / (sensor_sigma * sensor_sigma);
  for (const Interval& it : intervals) {
    r.push_back(g.add_pose(g.pose(r.back()) * it.odometry));  // odometry chaining
    g.emplace_factor<OdometryFactor>(r[r.size() - 2], r.back(), it.odometry, odo_info);
    g.emplace_factor<SensorMotionFactor>(r[r.size() - 2], r.back(), z, it.sensor, sensor_info);
  }
  const SolverSummary s = solve(g);
  ASSERT_TRUE(s.converged()) << s.full_report();
  // χ² of a consistent fit: about (number of residuals − parameters) = 6·300 − (3·300 + 4).
  EXPECT_GT(g.chi2(), 0.7 * 896);
  EXPECT_LT(g.chi2(), 1.3 * 896);
  const Eigen::Vector4d est = g.vector(z);
  const Eigen::Matrix4d cov = marginal_covariance(g, z);
  for (int i = 0; i < 4; ++i) {
    const double sigma = std::sqrt(cov(i, i));
    EXPECT_LT(std::abs(est[i] - kTruth[i]), 4 * sigma) << calibration_parameter_names()[static_cast<size_t>(i)] << ": " << est[i] << " vs " << kTruth[i] << " ± " << sigma;
    EXPECT_LT(sigma, 0.02);
  }
  const ObservabilityReport obs = analyse_observability(g, {z});
  EXPECT_TRUE(obs.observable()) << obs.describe();
}

TEST(GraphCalibration, NonholonomicGraphCannotSeeY) {
  // A metric sensor (height held at 1), nonholonomic factors only (paper fig. 3).
  Eigen::Vector4d truth = kTruth;
  truth[CI::kHeight] = 1.0;
  const auto intervals = simulate(200, truth, 0.0, 0.001, 2);
  FactorGraph g;
  const VariableId z = g.add_vector(Eigen::Vector4d(0.0, 0.0, 1.0, 0.0), "z", calibration_parameter_names());
  g.set_parameter_fixed(z, CI::kHeight);
  for (const Interval& it : intervals) g.emplace_factor<NonholonomicFactor>(z, it.sensor, 1e6);
  const ObservabilityReport obs = analyse_observability(g, {z});
  EXPECT_EQ(obs.rank, 2) << obs.describe();
  EXPECT_EQ(obs.unobservable, std::vector<std::string>{"z.y"}) << obs.describe();
  // With y held, x and yaw come out.
  g.set_parameter_fixed(z, CI::kY);
  ASSERT_TRUE(solve(g).converged());
  EXPECT_NEAR(g.vector(z)[CI::kX], truth[CI::kX], 2e-3);
  EXPECT_NEAR(g.vector(z)[CI::kYaw], truth[CI::kYaw], 2e-3);
  EXPECT_TRUE(analyse_observability(g, {z}).observable());
}

TEST(GraphCalibration, TurningInPlaceMakesYObservable) {
  Eigen::Vector4d truth = kTruth;
  truth[CI::kHeight] = 1.0;
  const auto intervals = simulate(200, truth, 0.0, 0.001, 3);
  FactorGraph g;
  const VariableId z = g.add_vector(Eigen::Vector4d(0.1, 0.0, 1.0, 0.0), "z", calibration_parameter_names());
  g.set_parameter_fixed(z, CI::kHeight);
  for (const Interval& it : intervals) {
    g.emplace_factor<NonholonomicFactor>(z, it.sensor, 1e6);
    if (it.direction == 0) g.emplace_factor<DirectionPriorFactor>(z, it.sensor, 0, 1e6);
  }
  EXPECT_TRUE(analyse_observability(g, {z}).observable());
  ASSERT_TRUE(solve(g).converged());
  EXPECT_NEAR(g.vector(z)[CI::kY], truth[CI::kY], 3e-3);
  EXPECT_NEAR(g.vector(z)[CI::kX], truth[CI::kX], 3e-3);
}

}  // namespace
}  // namespace planarvo::graph

namespace planarvo::graph {
namespace {

// A pair's residual (pair_residuals.h) is the minimum over the robot's free motion of the two
// factors' χ² (the odometry factor, eq. 25, and the sensor factor, eq. 26), which the solver finds
// on a two-pose graph with z held: the same χ², whatever the motions, noise models and z.
TEST(GraphPairResidual, IsTheTwoFactorGraphsMinimumWithTheMotionFree) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto rot3 = [](double t) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
    A.topLeftCorner<2, 2>() << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
    return A;
  };
  auto spd = [&](double scale) {
    Eigen::Matrix3d B;
    for (int i = 0; i < 9; ++i) B(i / 3, i % 3) = u(rng);
    return Eigen::Matrix3d(scale * scale * (B * B.transpose() + 0.2 * Eigen::Matrix3d::Identity()));
  };
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector4d z(0.3 * u(rng), 0.2 * u(rng), 0.15 + 0.1 * std::abs(u(rng)), 3.0 * u(rng));
    const SE2 sensor(0.5 * u(rng), 0.2 * u(rng), 0.6 * u(rng));
    const SE2 truth = sensor_to_robot_motion(sensor, z.data());
    const SE2 odometry = truth * SE2(0.01 * u(rng), 0.01 * u(rng), 0.02 * u(rng));
    const Eigen::Matrix3d C_o = spd(0.01), C_s = spd(0.005);  // of the right perturbations

    FactorGraph g;
    const VariableId zv = g.add_vector(z, "z", calibration_parameter_names());
    g.set_fixed(zv);
    const VariableId a = g.add_pose(SE2());
    g.set_fixed(a);
    const VariableId b = g.add_pose(odometry);
    g.emplace_factor<OdometryFactor>(a, b, odometry, Eigen::Matrix3d(C_o.inverse()));
    g.emplace_factor<SensorMotionFactor>(a, b, zv, sensor, Eigen::Matrix3d(C_s.inverse()));
    const SolverSummary s = solve(g);
    ASSERT_TRUE(s.converged()) << s.full_report();

    // The covariances of the motions' own (x, y, theta), as the calibration holds them.
    const Eigen::Matrix3d A_o = rot3(odometry.theta), A_s = rot3(sensor.theta);
    const PairResidual r =
        pair_residual(odometry, sensor, A_o * C_o * A_o.transpose(), A_s * C_s * A_s.transpose(), z);
    EXPECT_NEAR(r.chi2, g.chi2(), 1e-7 * (1.0 + g.chi2())) << trial;
    EXPECT_NEAR(r.d[2], std::remainder(odometry.theta - truth.theta, 2 * M_PI), 1e-12);
  }
}

}  // namespace
}  // namespace planarvo::graph
