// The odometry noise model fitted to residuals (graph/calibration/odometry_noise.h) against the model the
// residuals were drawn from.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "graph/calibration/odometry_noise.h"

namespace planarvo::graph {
namespace {

TEST(OdometryNoise, RecoversTheGeneratingModel) {
  // A differential drive's kind of noise: along travel 1.4 % of the distance, sideways almost
  // nothing, heading 0.2 mrad plus 1.5 % of the turn plus 0.05 rad per metre.
  OdometryNoiseModel truth;
  truth.constant = Eigen::Vector3d(0, 0, 2e-4 * 2e-4);
  truth.per_translation = Eigen::Vector3d(0.014 * 0.014, 1e-8, 0.05 * 0.05);
  truth.per_rotation = Eigen::Vector3d(1e-8, 0, 0.015 * 0.015);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> speed(0.0, 0.03), turn(-0.05, 0.05);
  std::normal_distribution<double> normal;
  std::vector<SE2> odometry;
  std::vector<Eigen::Vector3d> residual;
  for (int i = 0; i < 20000; ++i) {
    const double d = speed(rng), th = turn(rng);
    const SE2 m(d * std::cos(th / 2), d * std::sin(th / 2), th);
    const Eigen::Matrix3d c = truth.covariance(m);
    odometry.push_back(m);
    residual.emplace_back(std::sqrt(c(0, 0)) * normal(rng), std::sqrt(c(1, 1)) * normal(rng),
                          std::sqrt(c(2, 2)) * normal(rng));
  }
  const OdometryNoiseModel fit = fit_odometry_noise(odometry, residual);
  // The standard deviations the fit gives for typical motions within 12 % of the truth's (observed:
  // at most 10 %, along travel while turning in place).
  for (const SE2& m : {SE2(0.027, 0, 0), SE2(0.01, 0.0005, 0.04), SE2(0, 0, 0.05), SE2(0.02, 0, -0.03)})
    for (int c : {0, 2}) {
      const double s_true = std::sqrt(truth.covariance(m)(c, c)), s_fit = std::sqrt(fit.covariance(m)(c, c));
      EXPECT_NEAR(s_fit / s_true, 1.0, 0.12) << "component " << c << " at " << m.x << " " << m.theta;
    }
  // Sideways: tiny, and far below along travel.
  EXPECT_LT(fit.covariance(SE2(0.027, 0, 0))(1, 1), 0.01 * fit.covariance(SE2(0.027, 0, 0))(0, 0));
  // Coefficients are never negative.
  EXPECT_GE(fit.constant.minCoeff(), 0.0);
  EXPECT_GE(fit.per_translation.minCoeff(), 0.0);
  EXPECT_GE(fit.per_rotation.minCoeff(), 0.0);
}

TEST(OdometryNoise, TooFewIntervalsGiveTheFloors) {
  const OdometryNoiseModel fit = fit_odometry_noise({SE2(0.01, 0, 0)}, {Eigen::Vector3d(1e-3, 0, 0)});
  EXPECT_DOUBLE_EQ(fit.covariance(SE2(0.01, 0, 0))(0, 0), fit.floor_translation * fit.floor_translation);
}

}  // namespace
}  // namespace planarvo::graph
