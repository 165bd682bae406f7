// calibrate() with the nonholonomic method (paper sec. 5.2.2, eqs. 28-31 in this project's
// conventions) on simulated motions of a known z: the arc form exact, the velocity form's floor,
// the branch chosen by labels (or odometry) and reported ambiguous without them, y from the
// direction prior (exact with labels 0, an interval with ±1 only, checked against an independent
// computation and against DirectionPriorFactor), NEES, gross errors and degenerate drives.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "graph/calibration/calibration.h"
#include "graph/calibration/calibration_init.h"
#include "graph/solver/factor_graph.h"
#include "graph/calibration/factors.h"
#include "unit/graph_calibration_sim.h"

namespace planarvo::graph {
namespace {

using test::CalibrationSim;
using test::Drive;
using test::simulate_motions;

// The paper's camera configuration 1 (conventions.md); the height is known to this method.
const std::array<double, 4> kTruth = {0.2441, -0.0185, 0.1787, -9.2 * M_PI / 180};

CalibrationOptions nonholonomic() {
  CalibrationOptions o;
  o.method = CalibrationMethod::Nonholonomic;
  o.fixed_scale = kTruth[2];
  return o;
}

CalibrationSim noisy_sim(unsigned seed, int intervals = 120) {
  CalibrationSim sim;
  sim.intervals = intervals;
  sim.seed = seed;
  sim.sensor_sigma_t = 0.003 / kTruth[2];
  sim.sensor_sigma_theta = 0.003;
  sim.odometry = false;
  return sim;
}

double dyaw(const CalibrationResult& r, double yaw) { return wrap_angle(r.value[3] - yaw); }

TEST(GraphCalibrationNonholonomic, ClosedFormIsExactUpToTheBranch) {
  std::vector<SE2> sensor;
  for (const MotionSample& s : simulate_motions(kTruth, CalibrationSim{}).samples) sensor.push_back(s.sensor.value);
  const auto c = calibration_detail::nonholonomic_closed_form(sensor, kTruth[2]);
  const bool flipped = std::abs(wrap_angle(c[1] - kTruth[3])) > M_PI / 2;
  EXPECT_NEAR(c[0], flipped ? -kTruth[0] : kTruth[0], 1e-9);
  EXPECT_NEAR(wrap_angle(c[1] - kTruth[3] - (flipped ? M_PI : 0.0)), 0.0, 1e-9);
}

TEST(GraphCalibrationNonholonomic, ArcFormAndLabelsZeroRecoverZExactly) {
  CalibrationSim sim;
  sim.odometry = false;
  const CalibrationResult r = calibrate(simulate_motions(kTruth, sim).samples, nonholonomic());
  ASSERT_TRUE(r.ok()) << r.unobservable_reason;
  EXPECT_FALSE(r.ambiguous);
  EXPECT_NEAR(r.value[0], kTruth[0], 1e-9);
  EXPECT_NEAR(dyaw(r, kTruth[3]), 0.0, 1e-9);
  // Turning in place (label 0) pins y exactly once x and yaw are right.
  EXPECT_NEAR(r.value[1], kTruth[1], 1e-9);
  EXPECT_EQ(r.value[2], kTruth[2]);
  EXPECT_EQ(r.estimated, (std::array<bool, 4>{true, true, false, true}));
  EXPECT_EQ(r.direction_counts, (std::array<int, 3>{125, 50, 125}));
  ASSERT_TRUE(r.y_interval.has_value());
  EXPECT_NEAR((*r.y_interval)[1] - (*r.y_interval)[0], 0.0, 1e-9);
}

// Labels ±1 only: y is left in the interval where every labelled forward motion has its label's
// sign. Computed here independently from the true motions: a forward motion
// m_r,x(y) = m_r,x(y_true) + sin θ (y − y_true) keeps its sign for y on one side of
// y_true − m_r,x(y_true) / sin θ. This is the direction prior's floor.
TEST(GraphCalibrationNonholonomic, LabelsPlusMinusOneOnlyBoundY) {
  CalibrationSim sim;
  sim.odometry = false;
  auto data = simulate_motions(kTruth, sim);
  for (MotionSample& s : data.samples)
    if (*s.direction == 0) s.direction.reset();
  double lo = -1e300, hi = 1e300;
  for (size_t i = 0; i < data.samples.size(); ++i) {
    const auto& s = data.samples[i];
    const double st = std::sin(data.robot[i].theta);
    if (!s.direction || std::abs(st) < 1e-12) continue;
    const double bound = kTruth[1] - data.robot[i].x / st;
    // label·(m + st (y − y_true)) ≥ 0
    if (*s.direction * st > 0) lo = std::max(lo, bound);
    else hi = std::min(hi, bound);
  }
  const CalibrationResult r = calibrate(data.samples, nonholonomic());
  ASSERT_TRUE(r.y_interval.has_value());
  EXPECT_NEAR((*r.y_interval)[0], lo, 1e-9);
  EXPECT_NEAR((*r.y_interval)[1], hi, 1e-9);
  EXPECT_LT(lo, kTruth[1]);
  EXPECT_GT(hi, kTruth[1]);
  EXPECT_NEAR(r.value[1], 0.5 * (lo + hi), 1e-9);
  // The reported σ covers the interval (half its width at least), and says it is too wide.
  EXPECT_GE(std::sqrt(r.covariance(1, 1)), 0.5 * (hi - lo));
  EXPECT_FALSE(r.observable[1]);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.unobservable_reason.find("no turning in place"), std::string::npos) << r.unobservable_reason;
  // x and yaw are unaffected.
  EXPECT_TRUE(r.observable[0] && r.observable[3]);
  EXPECT_NEAR(r.value[0], kTruth[0], 1e-9);
}

// The velocity form assumes no lateral motion over an interval, which an arc has
// (v ω Δt² / 2): a bias that shrinks with the motion per interval (measured on these drives,
// speeds 0.1-0.4 m/s, |ω| ≤ 0.8 rad/s: x up to 4 mm and yaw up to 0.56° at Δt = 1 s, under 1 mm
// and 0.07° at Δt = 0.1 s). The arc form is exact on the same motions.
TEST(GraphCalibrationNonholonomic, VelocityFormHasAFloorThatShrinksWithTheInterval) {
  CalibrationOptions o = nonholonomic();
  o.nonholonomic_form = CalibrationOptions::NonholonomicForm::Velocity;
  double rms_x[2] = {0.0, 0.0}, rms_yaw[2] = {0.0, 0.0};
  for (int j = 0; j < 2; ++j)
    for (unsigned seed = 1; seed <= 4; ++seed) {
      CalibrationSim sim;
      sim.odometry = false;
      sim.dt = j == 0 ? 1.0 : 0.1;
      sim.seed = seed;
      const auto samples = simulate_motions(kTruth, sim).samples;
      const CalibrationResult r = calibrate(samples, o);
      rms_x[j] += 0.25 * std::pow(r.value[0] - kTruth[0], 2);
      rms_yaw[j] += 0.25 * std::pow(dyaw(r, kTruth[3]), 2);
      if (j == 0) {
        const CalibrationResult arc = calibrate(samples, nonholonomic());
        EXPECT_NEAR(arc.value[0], kTruth[0], 1e-9);
        EXPECT_NEAR(dyaw(arc, kTruth[3]), 0.0, 1e-9);
      }
    }
  EXPECT_GT(std::sqrt(rms_x[0]), 1e-3);
  EXPECT_GT(std::sqrt(rms_yaw[0]), 0.1 * M_PI / 180);
  EXPECT_LT(rms_x[1], rms_x[0] / 9.0);
  EXPECT_LT(rms_yaw[1], rms_yaw[0] / 9.0);
}

TEST(GraphCalibrationNonholonomic, ConvergesFromPoorAndWrongBranchStarts) {
  CalibrationSim sim;
  sim.odometry = false;
  const auto samples = simulate_motions(kTruth, sim).samples;
  CalibrationOptions o = nonholonomic();
  for (auto start : std::vector<std::array<double, 4>>{
           {0.2, 0.0, 0.0, 0.0},                        // the paper's
           {0.2, 0.0, 0.0, kTruth[3] + 2.1},            // yaw 120° off
           {0.2, 0.0, 0.0, kTruth[3] - 2.1},
           {-kTruth[0], 0.0, 0.0, kTruth[3] + M_PI}}) {  // the other branch, exactly
    o.initial = start;
    const CalibrationResult r = calibrate(samples, o);
    EXPECT_TRUE(r.ok()) << r.unobservable_reason;
    EXPECT_NEAR(r.value[0], kTruth[0], 1e-9);
    EXPECT_NEAR(r.value[1], kTruth[1], 1e-9);
    EXPECT_NEAR(dyaw(r, kTruth[3]), 0.0, 1e-9);
  }
}

TEST(GraphCalibrationNonholonomic, WithoutLabelsTheBranchIsAmbiguous) {
  CalibrationSim sim;
  sim.odometry = false;
  sim.labels = false;
  const CalibrationResult r = calibrate(simulate_motions(kTruth, sim).samples, nonholonomic());
  EXPECT_TRUE(r.ambiguous);
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.estimated[1]);
  EXPECT_NE(r.unobservable_reason.find("no forward or backward direction labels"), std::string::npos) << r.unobservable_reason;
  // One of the two branches, exactly.
  const bool flipped = std::abs(dyaw(r, kTruth[3])) > M_PI / 2;
  EXPECT_NEAR(r.value[0], flipped ? -kTruth[0] : kTruth[0], 1e-9);
  EXPECT_NEAR(wrap_angle(r.value[3] - kTruth[3] - (flipped ? M_PI : 0.0)), 0.0, 1e-9);
}

TEST(GraphCalibrationNonholonomic, LabelsOrOdometryChooseTheBranch) {
  // A sensor facing backwards (yaw near π), where the "|yaw| < 90°" convention would be wrong.
  const std::array<double, 4> truth = {-0.15, 0.04, 0.3, 2.8};
  CalibrationOptions o = nonholonomic();
  o.fixed_scale = truth[2];
  for (bool labels : {true, false}) {
    CalibrationSim sim;
    sim.labels = labels;  // without labels, the odometry's sign gives them
    sim.odometry = !labels;
    const CalibrationResult r = calibrate(simulate_motions(truth, sim).samples, o);
    EXPECT_TRUE(r.ok()) << r.unobservable_reason;
    EXPECT_FALSE(r.ambiguous);
    EXPECT_NEAR(r.value[0], truth[0], 1e-9);
    EXPECT_NEAR(r.value[1], truth[1], 1e-9);
    EXPECT_NEAR(dyaw(r, truth[3]), 0.0, 1e-9);
  }
}

TEST(GraphCalibrationNonholonomic, CovarianceIsConsistentOverManySeeds) {
  constexpr int kRuns = 200;
  double sum = 0.0;
  for (unsigned seed = 1; seed <= kRuns; ++seed) {
    const CalibrationResult r = calibrate(simulate_motions(kTruth, noisy_sim(seed)).samples, nonholonomic());
    ASSERT_TRUE(r.ok()) << "seed " << seed << ": " << r.unobservable_reason;
    const Eigen::Vector3d e(r.value[0] - kTruth[0], r.value[1] - kTruth[1], dyaw(r, kTruth[3]));
    Eigen::Matrix3d C;
    const int idx[3] = {0, 1, 3};
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) C(a, b) = r.covariance(idx[a], idx[b]);
    sum += e.dot(C.ldlt().solve(e));
  }
  // 99% interval of the mean of 200 χ²(3) values (Wilson–Hilferty for χ²(600)).
  const double k = 3.0 * kRuns, c = 2.0 / (9.0 * k);
  const double lo = k * std::pow(1.0 - c - 2.5758 * std::sqrt(c), 3) / kRuns;
  const double hi = k * std::pow(1.0 - c + 2.5758 * std::sqrt(c), 3) / kRuns;
  EXPECT_GT(sum / kRuns, lo);
  EXPECT_LT(sum / kRuns, hi);
}

TEST(GraphCalibrationNonholonomic, GrossSensorErrorsAreGatedWithoutBias) {
  CalibrationSim clean = noisy_sim(11, 300), dirty = clean;
  dirty.outlier_fraction = 0.02;
  const auto a = simulate_motions(kTruth, clean), b = simulate_motions(kTruth, dirty);
  const CalibrationResult ra = calibrate(a.samples, nonholonomic());
  const CalibrationResult rb = calibrate(b.samples, nonholonomic());
  ASSERT_TRUE(rb.ok()) << rb.unobservable_reason;
  // A gross error along the constraint's blind direction does not show; those that do are gated.
  EXPECT_GE(rb.outliers, static_cast<int>(b.outliers.size()) / 2);
  EXPECT_LE(rb.outliers, static_cast<int>(b.outliers.size()) + 2);
  for (int i : rb.outlier_samples)
    EXPECT_NE(std::find(b.outliers.begin(), b.outliers.end(), i), b.outliers.end()) << i;
  for (int k : {0, 1, 3})
    EXPECT_LT(std::abs(rb.value[static_cast<size_t>(k)] - ra.value[static_cast<size_t>(k)]),
              0.5 * std::sqrt(ra.covariance(k, k)))
        << k;
}

TEST(GraphCalibrationNonholonomic, DrivingStraightLeavesXUnobservable) {
  CalibrationSim sim = noisy_sim(12, 200);
  sim.drive = Drive::StraightOnly;
  const CalibrationResult r = calibrate(simulate_motions(kTruth, sim).samples, nonholonomic());
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.observable[0]);
  EXPECT_TRUE(r.observable[3]);
  EXPECT_NEAR(dyaw(r, kTruth[3]), 0.0, 4.0 * std::sqrt(r.covariance(3, 3)));
  EXPECT_NE(r.unobservable_reason.find("driving straight only (no rotation): x is not observable"),
            std::string::npos)
      << r.unobservable_reason;
}

TEST(GraphCalibrationNonholonomic, OneCircleIsDegenerate) {
  for (bool noise : {false, true}) {
    CalibrationSim sim = noisy_sim(13, 200);
    sim.drive = Drive::OneCircle;
    if (!noise) sim.sensor_sigma_t = sim.sensor_sigma_theta = 0.0;
    const CalibrationResult r = calibrate(simulate_motions(kTruth, sim).samples, nonholonomic());
    EXPECT_FALSE(r.ok());
    EXPECT_FALSE(r.observable[0]);
    EXPECT_FALSE(r.observable[3]);
    EXPECT_NE(r.unobservable_reason.find("one circle only"), std::string::npos) << r.unobservable_reason;
  }
}

TEST(GraphCalibrationNonholonomic, ForwardOnlyGentleTurnsLeaveYUnobservable) {
  CalibrationSim sim = noisy_sim(14, 200);
  sim.drive = Drive::ForwardOnly;
  sim.omega_max = 0.3;  // turning radii of 0.33 m and more
  const CalibrationResult r = calibrate(simulate_motions(kTruth, sim).samples, nonholonomic());
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.observable[0] && r.observable[3]) << r.unobservable_reason;
  EXPECT_TRUE(r.estimated[1]);
  EXPECT_FALSE(r.observable[1]);
  EXPECT_NE(r.unobservable_reason.find("no turning in place"), std::string::npos) << r.unobservable_reason;
  EXPECT_NE(r.unobservable_reason.find("no backward motion"), std::string::npos) << r.unobservable_reason;
  // Honest: the truth lies in the interval reported, and within the σ.
  ASSERT_TRUE(r.y_interval.has_value());
  EXPECT_LT((*r.y_interval)[0] - 0.01, kTruth[1]);
  EXPECT_GT((*r.y_interval)[1] + 0.01, kTruth[1]);
  EXPECT_LT(std::abs(r.value[1] - kTruth[1]), std::sqrt(r.covariance(1, 1)));
}

// Labels that contradict the motions: 10% flipped at random, or intervals turning more than half
// a turn (driving forwards then moves the robot backwards over the interval). Gating them one by
// one would leave a consistent but wrong subset (measured: y 50 mm off at a σ of 10 mm): y is
// reported unobservable instead, while x and yaw (which need the labels only for the branch)
// stay right.
TEST(GraphCalibrationNonholonomic, ContradictingLabelsLeaveYUntrusted) {
  for (int variant = 0; variant < 2; ++variant) {
    CalibrationSim sim;
    sim.odometry = false;
    if (variant == 1) sim.omega_max = 5.0;  // up to 5 rad per 1 s interval
    auto data = simulate_motions(kTruth, sim);
    for (size_t i = 0; i < data.samples.size(); ++i) {
      auto& d = data.samples[i].direction;
      if (variant == 0 && *d != 0 && i % 10 == 3) d = -*d;
      if (variant == 1 && *d == 0) d.reset();
    }
    const CalibrationResult r = calibrate(data.samples, nonholonomic());
    EXPECT_FALSE(r.ok());
    EXPECT_FALSE(r.ambiguous);
    EXPECT_FALSE(r.observable[1]);
    EXPECT_NE(r.unobservable_reason.find("direction labels contradict the motions"), std::string::npos)
        << r.unobservable_reason;
    EXPECT_NEAR(r.value[0], kTruth[0], 1e-9);
    EXPECT_NEAR(dyaw(r, kTruth[3]), 0.0, 1e-9);
  }
}

// The one-dimensional direction prior against the graph's DirectionPriorFactor (eq. 31), and
// its one-sigma region against the curvature of a quadratic cost.
TEST(GraphCalibrationNonholonomic, DirectionPriorMatchesTheFactor) {
  CalibrationSim sim = noisy_sim(15, 60);
  const auto data = simulate_motions(kTruth, sim);
  Eigen::Vector4d z(kTruth[0], 0.0, kTruth[2], kTruth[3]);
  FactorGraph g;
  const VariableId zid = g.add_vector(z, "z", calibration_parameter_names());
  std::vector<calibration_detail::PriorTerm> terms;
  for (size_t i = 0; i < data.samples.size(); ++i) {
    const auto& s = data.samples[i];
    const double w = 1e4 * (1.0 + static_cast<double>(i % 3));
    g.add_factor(std::make_unique<DirectionPriorFactor>(zid, s.sensor.value, *s.direction, w));
    calibration_detail::PriorTerm t;
    t.alpha = sensor_to_robot_motion(s.sensor.value, z.data()).x;
    t.beta = std::sin(s.sensor.value.theta);
    t.weight = w;
    t.label = *s.direction;
    terms.push_back(t);
  }
  for (double y : {-0.3, -0.05, -0.0185, 0.0, 0.2}) {
    z[1] = y;
    g.set_vector(zid, z);
    EXPECT_NEAR(calibration_detail::direction_prior_cost(terms, y), g.chi2(), 1e-9 * g.chi2()) << y;
  }
  // Labels 0 only: a quadratic; the region where the cost is within 1 of its minimum is ±σ.
  std::vector<calibration_detail::PriorTerm> zeros;
  double info = 0.0, num = 0.0;
  for (const auto& t : terms)
    if (t.label == 0) zeros.push_back(t), info += t.weight * t.beta * t.beta, num -= t.weight * t.beta * t.alpha;
  const auto sol = calibration_detail::solve_direction_prior(zeros, 1.0);
  EXPECT_NEAR(sol.estimate, num / info, 1e-12);
  EXPECT_NEAR(0.5 * (sol.region_hi - sol.region_lo), 1.0 / std::sqrt(info), 1e-9);
}

}  // namespace
}  // namespace planarvo::graph
