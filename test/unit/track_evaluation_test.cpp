// The accuracy figures against hand-computable cases.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "track/evaluation.h"

namespace planarvo::track {
namespace {

TEST(TrackEvaluation, ExactEstimateIsPerfect) {
  std::vector<SE2> m = {{0.01, 0, 0.02}, {0.012, 0, -0.01}, {-0.005, 0, 0.0}};
  const auto a = evaluate_motions(m, m, {0.1, 0.1, 0.1});
  EXPECT_EQ(a.intervals, 3);
  EXPECT_DOUBLE_EQ(a.rms_translation, 0.0);
  EXPECT_NEAR(a.slope_linear, 1.0, 1e-12);
  EXPECT_NEAR(a.slope_angular, 1.0, 1e-12);
  EXPECT_NEAR(a.distance, 0.027, 1e-15);
  EXPECT_EQ(a.gross_errors, 0);
}

TEST(TrackEvaluation, ScaledEstimateGivesItsScaleAsSlopeAndDrift) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  std::vector<SE2> truth, est;
  for (int i = 0; i < 200; ++i) {
    const double x = std::abs(u(rng)), th = u(rng);
    truth.emplace_back(x, 0, th);
    est.emplace_back(1.02 * x, 0, 0.99 * th);
  }
  const auto a = evaluate_motions(est, truth, std::vector<double>(200, 1.0 / 30));
  EXPECT_NEAR(a.slope_linear, 1.02, 1e-12);
  EXPECT_NEAR(a.slope_angular, 0.99, 1e-12);
  EXPECT_GT(a.endpoint_drift, 0.0);
}

TEST(TrackEvaluation, StraightLineDriftIsTheScaleError) {
  std::vector<SE2> truth(100, SE2(0.01, 0, 0)), est(100, SE2(0.0101, 0.0001, 0));
  const auto a = evaluate_motions(est, truth, std::vector<double>(100, 0.1), 1e-4);
  EXPECT_NEAR(a.distance, 1.0, 1e-12);
  EXPECT_NEAR(a.endpoint_error, std::hypot(0.01, 0.01), 1e-12);
  EXPECT_NEAR(a.endpoint_drift, std::hypot(0.01, 0.01), 1e-12);
  EXPECT_NEAR(a.rms_translation, std::hypot(1e-4, 1e-4), 1e-15);
  EXPECT_EQ(a.gross_errors, 100);  // each 0.14 mm error is over the 0.1 mm threshold given
}

TEST(TrackEvaluation, InvalidIntervalsAreLeftOutOfPerFrameFigures) {
  std::vector<SE2> truth(3, SE2(0.01, 0, 0)), est = truth;
  est[1] = SE2(0.5, 0, 0);
  const auto a = evaluate_motions(est, truth, {0.1, 0.1, 0.1}, 1e-3, {true, false, true});
  EXPECT_EQ(a.intervals, 2);
  EXPECT_EQ(a.gross_errors, 0);
  EXPECT_NEAR(a.endpoint_error, 0.49, 1e-12);  // the composed trajectory still carries it
}

TEST(TrackEvaluation, MismatchedSizesAreAnError) {
  EXPECT_THROW(evaluate_motions({SE2()}, {}, {}), Error);
}

}  // namespace
}  // namespace planarvo::track
