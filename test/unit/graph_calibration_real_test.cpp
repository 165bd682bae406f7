// The graph calibrations on real data: Censi et al.'s laser scanner on a differential-drive robot
// (shared/data/real/censi2011), metric motions (scale fixed at 1), about 1-5% scan-matching
// failures. lmov against the archive's own result (its method estimated the wheel parameters
// jointly); the nonholonomic method, with labels from the odometry's sign, against the odometry
// method on the same files.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/test_util.h"
#include "graph/calibration/calibration.h"
#include "io/motions.h"

namespace planarvo::graph {
namespace {

std::vector<MotionSample> censi(const std::string& name) {
  const auto pairs = io::read_motion_pairs(
      (test::shared_dir() / "data" / "real" / "censi2011" / (name + "_motions.csv")).string());
  std::vector<MotionSample> samples;
  for (const io::MotionPair& p : pairs.pairs) {
    MotionSample s;
    s.interval = p.interval;
    s.sensor = p.sensor;
    s.odometry = p.odometry;
    s.direction = p.direction;
    samples.push_back(s);
  }
  return samples;
}

CalibrationOptions metric(CalibrationMethod method) {
  CalibrationOptions o;
  o.method = method;
  o.fix_scale = true;
  o.fixed_scale = 1.0;
  return o;
}

// lmov_reference_result.json: l_x, l_y, l_theta and the square roots of their covariance.
TEST(GraphCalibrationReal, CensiLmovOdometryAgreesWithTheArchive) {
  const auto samples = censi("lmov");
  ASSERT_GT(samples.size(), 4000u);
  const CalibrationResult r = calibrate(samples, metric(CalibrationMethod::Odometry));
  ASSERT_TRUE(r.ok()) << r.unobservable_reason << "\n" << r.summary.full_report();
  EXPECT_NEAR(r.value[0], -0.00587095, std::sqrt(1.59008e-06));
  EXPECT_NEAR(r.value[1], -0.0387078, std::sqrt(4.53146e-07));
  EXPECT_NEAR(wrap_angle(r.value[3] - -1.86026), 0.0, std::sqrt(0.000435694));
  // The scan-matching failures are gated: a few percent of the rows (measured 4.9%), not more.
  EXPECT_GT(r.outliers, static_cast<int>(0.01 * samples.size()));
  EXPECT_LT(r.outliers, static_cast<int>(0.08 * samples.size()));
}

// Without the gate and the loss the failures move the answer by several of its own standard
// deviations (measured: x 4.3 σ, y 7.5 σ), though still within the archive's looser ones (which
// include the wheel parameters' uncertainty): the robustness is needed at this precision.
TEST(GraphCalibrationReal, CensiLmovPlainLeastSquaresIsBiased) {
  const auto samples = censi("lmov");
  const CalibrationResult r = calibrate(samples, metric(CalibrationMethod::Odometry));
  CalibrationOptions o = metric(CalibrationMethod::Odometry);
  o.loss = RobustLoss::None;
  o.gate_sigma = 0.0;
  const CalibrationResult rp = calibrate(samples, o);
  const double dx = std::abs(rp.value[0] - r.value[0]) / std::sqrt(r.covariance(0, 0));
  const double dy = std::abs(rp.value[1] - r.value[1]) / std::sqrt(r.covariance(1, 1));
  EXPECT_GT(std::max(dx, dy), 3.0) << rp.value[0] << " " << rp.value[1];
}

// The archive's standard deviations for lmov (x, y, yaw): this robot's calibration uncertainty
// with the wheel parameters free. The odometry method's own σ is conditional on the wheel
// parameters the odometry was computed with, and far smaller (0.09 mm, 0.08 mm, 0.0017 rad).
constexpr double kArchiveSigma[3] = {1.26e-3, 0.673e-3, 0.0209};

// The nonholonomic method sees no odometry but its sign. On all three files its x, y and yaw
// agree with the odometry method's within the archive's deviations, and on lmov with the
// archive's values. (They do not agree within the two methods' own σ: on lmov y differs by
// 0.55 mm at σ 0.11 mm, the direction prior alone at the odometry method's x and yaw by
// 0.39 mm, a systematic difference between the models that no residual shows.)
TEST(GraphCalibrationReal, CensiNonholonomicAgreesWithOdometryAndTheArchive) {
  for (const char* name : {"lstraight", "l90", "lmov"}) {
    const auto samples = censi(name);
    const CalibrationResult ro = calibrate(samples, metric(CalibrationMethod::Odometry));
    const CalibrationResult rn = calibrate(samples, metric(CalibrationMethod::Nonholonomic));
    ASSERT_TRUE(ro.ok()) << name << ": " << ro.unobservable_reason;
    ASSERT_TRUE(rn.ok()) << name << ": " << rn.unobservable_reason;
    EXPECT_FALSE(rn.ambiguous);
    EXPECT_GT(rn.direction_counts[1], 1000) << name;  // turning in place, labelled 0 by odometry
    const int idx[3] = {0, 1, 3};
    for (int j = 0; j < 3; ++j) {
      const auto k = static_cast<size_t>(idx[j]);
      const double d = j == 2 ? wrap_angle(rn.value[k] - ro.value[k]) : rn.value[k] - ro.value[k];
      EXPECT_LT(std::abs(d), kArchiveSigma[j]) << name << " parameter " << idx[j];
    }
    if (std::string(name) == "lmov") {
      EXPECT_NEAR(rn.value[0], -0.00587095, kArchiveSigma[0]);
      EXPECT_NEAR(rn.value[1], -0.0387078, kArchiveSigma[1]);
      EXPECT_NEAR(wrap_angle(rn.value[3] - -1.86026), 0.0, kArchiveSigma[2]);
    }
  }
}

}  // namespace
}  // namespace planarvo::graph
