// planarvo_motion_pairs_load / _save and planarvo_calibrate through the C API alone, against
// independent references: files written here by hand (every value read back exactly, every
// malformed line a PLANARVO_ERROR_INVALID_INPUT naming the file and the line), random pairs
// saved and loaded again bit for bit, and motions simulated from known extrinsics (the answer is
// the truth, within the reported standard deviations when the motions are noisy). Also every bad
// argument of planarvo_calibrate. (capi_calibration_test.cpp compares planarvo_calibrate with
// graph::calibrate on the same samples.)
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/test_util.h"
#include "core/extrinsics_estimate.h"
#include "graph/calibration/calibration_extrinsics.h"
#include "io/formats.h"
#include "planarvo/planarvo.h"
#include "unit/graph_calibration_sim.h"

namespace planarvo {
namespace {

using test::CalibrationSim;

const std::array<double, 4> kTruth = {0.2441, -0.0185, 0.1787, -9.2 * M_PI / 180};

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// Stores a value that no enumerator has, as a C caller can.
template <typename E>
void set_enum(E* e, int v) {
  static_assert(sizeof(E) == sizeof(int));
  std::memcpy(e, &v, sizeof v);
}

bool mentions(const std::string& what) { return std::string(planarvo_last_error()).find(what) != std::string::npos; }

std::vector<planarvo_motion_pair> load(const std::string& path, planarvo_status expected = PLANARVO_OK) {
  size_t n = 0;
  const planarvo_status st = planarvo_motion_pairs_load(path.c_str(), nullptr, 0, &n);
  EXPECT_EQ(st, expected) << planarvo_last_error();
  if (st != PLANARVO_OK) return {};
  std::vector<planarvo_motion_pair> pairs(n);
  for (planarvo_motion_pair& p : pairs) planarvo_motion_pair_init(&p);
  EXPECT_EQ(planarvo_motion_pairs_load(path.c_str(), pairs.data(), n, &n), PLANARVO_OK) << planarvo_last_error();
  return pairs;
}

// The simulated samples as C motion pairs, without their covariances (the options' noise model).
std::vector<planarvo_motion_pair> simulated_pairs(const CalibrationSim& sim) {
  const auto samples = test::simulate_motions(kTruth, sim).samples;
  std::vector<planarvo_motion_pair> pairs(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    const graph::MotionSample& s = samples[i];
    planarvo_motion_pair& p = pairs[i];
    planarvo_motion_pair_init(&p);
    p.interval = s.interval;
    p.sensor = {s.sensor.value.x, s.sensor.value.y, s.sensor.value.theta};
    p.has_odometry = s.odometry.has_value();
    if (s.odometry) p.odometry = {s.odometry->value.x, s.odometry->value.y, s.odometry->value.theta};
    p.has_direction = s.direction.has_value();
    if (s.direction) p.direction = *s.direction;
  }
  return pairs;
}

planarvo_calibration_result calibrate(const std::vector<planarvo_motion_pair>& pairs,
                                      const planarvo_calibration_options* o, planarvo_status expected = PLANARVO_OK) {
  planarvo_calibration_result r;
  std::memset(&r, 0, sizeof r);
  r.struct_size = sizeof r;
  EXPECT_EQ(planarvo_calibrate(pairs.data(), pairs.size(), o, &r), expected) << planarvo_last_error();
  return r;
}

// ---- planarvo_motion_pairs_load / _save ----------------------------------------------------

// Columns in another order, comment and blank lines, a '+1' label, exponents: read as written.
TEST(CApiMotionPairsFile, ColumnsInAnyOrderCommentsAndBlankLines) {
  test::ScratchDir d;
  const std::string path = (d / "pairs.csv").string();
  write(path,
        "# direction, sensor_dtheta, odo_dtheta, interval_s, sensor_dy, odo_dy, sensor_dx, odo_dx\n"
        "# a comment line\n"
        "\n"
        "+1, 0.125, 0.25, 0.03125, -2.5e-3, 1e-5, 0.0078125, 0.5\n"
        "   -1 ,-0.5,-0.4, 2, 0, -0, -1.25E+1, -3\n");
  const auto pairs = load(path);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].direction, 1);
  EXPECT_EQ(pairs[0].sensor.theta, 0.125);
  EXPECT_EQ(pairs[0].odometry.theta, 0.25);
  EXPECT_EQ(pairs[0].interval, 0.03125);
  EXPECT_EQ(pairs[0].sensor.y, -2.5e-3);
  EXPECT_EQ(pairs[0].odometry.y, 1e-5);
  EXPECT_EQ(pairs[0].sensor.x, 0.0078125);
  EXPECT_EQ(pairs[0].odometry.x, 0.5);
  EXPECT_EQ(pairs[1].direction, -1);
  EXPECT_EQ(pairs[1].sensor.theta, -0.5);
  EXPECT_EQ(pairs[1].odometry.theta, -0.4);
  EXPECT_EQ(pairs[1].interval, 2.0);
  EXPECT_EQ(pairs[1].sensor.x, -12.5);
  EXPECT_EQ(pairs[1].odometry.x, -3.0);
  for (const planarvo_motion_pair& p : pairs) {
    EXPECT_EQ(p.has_odometry, 1);
    EXPECT_EQ(p.has_direction, 1);
  }
}

// Without a direction column the label is the sign of the odometry's forward motion, 0 below
// 1 mm/s (the default still speed) over the interval.
TEST(CApiMotionPairsFile, LabelsFromTheOdometryWithoutADirectionColumn) {
  test::ScratchDir d;
  const std::string path = (d / "pairs.csv").string();
  write(path, "# interval_s,odo_dx,odo_dy,odo_dtheta,sensor_dx,sensor_dy,sensor_dtheta\n"
              "1,0.1,0,0,0.1,0,0\n2,-0.1,0,0,-0.1,0,0\n2,0.0019,0,0.5,0,0,0.5\n0.5,-0.0006,0,0.5,0,0,0.5\n");
  const auto pairs = load(path);
  ASSERT_EQ(pairs.size(), 4u);
  const int expected[4] = {1, -1, 0, -1};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(pairs[i].has_direction, 1) << i;
    EXPECT_EQ(pairs[i].direction, expected[i]) << i;
  }
}

// Random pairs saved and loaded: every double back bit for bit.
TEST(CApiMotionPairsFile, SavedPairsLoadBackExactly) {
  test::ScratchDir d;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const bool odometry : {true, false}) {
    std::vector<planarvo_motion_pair> pairs(50);
    for (size_t i = 0; i < pairs.size(); ++i) {
      planarvo_motion_pair& p = pairs[i];
      planarvo_motion_pair_init(&p);
      p.interval = 0.01 + std::abs(u(rng)) * std::pow(10.0, static_cast<double>(i % 7) - 3);
      p.sensor = {u(rng) * 1e-3, u(rng), u(rng) * 3};
      p.has_odometry = odometry;
      p.odometry = odometry ? planarvo_se2{u(rng) * 1e5, u(rng) * 1e-9, u(rng)} : planarvo_se2{0, 0, 0};
      p.has_direction = 1;
      p.direction = static_cast<int32_t>(i % 3) - 1;
    }
    const std::string path = (d / (odometry ? "with.csv" : "without.csv")).string();
    ASSERT_EQ(planarvo_motion_pairs_save(path.c_str(), pairs.data(), pairs.size()), PLANARVO_OK)
        << planarvo_last_error();
    const auto back = load(path);
    ASSERT_EQ(back.size(), pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
      const planarvo_motion_pair &a = pairs[i], &b = back[i];
      EXPECT_EQ(b.interval, a.interval) << i;
      EXPECT_EQ(b.sensor.x, a.sensor.x) << i;
      EXPECT_EQ(b.sensor.y, a.sensor.y) << i;
      EXPECT_EQ(b.sensor.theta, a.sensor.theta) << i;
      EXPECT_EQ(b.has_odometry, a.has_odometry) << i;
      EXPECT_EQ(b.odometry.x, a.odometry.x) << i;
      EXPECT_EQ(b.odometry.y, a.odometry.y) << i;
      EXPECT_EQ(b.odometry.theta, a.odometry.theta) << i;
      EXPECT_EQ(b.direction, a.direction) << i;
    }
  }
  // Pairs of different columns cannot share a file.
  std::vector<planarvo_motion_pair> mixed(2);
  for (planarvo_motion_pair& p : mixed) {
    planarvo_motion_pair_init(&p);
    p.interval = 1;
  }
  mixed[1].has_odometry = 1;
  const std::string path = (d / "mixed.csv").string();
  EXPECT_EQ(planarvo_motion_pairs_save(path.c_str(), mixed.data(), 2), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_FALSE(std::filesystem::exists(path));
}

// Each malformed file: PLANARVO_ERROR_INVALID_INPUT, the message naming file:line and the fault.
TEST(CApiMotionPairsFile, MalformedLinesAreInvalidInputNamingTheLine) {
  test::ScratchDir d;
  const std::string kHeader = "# interval_s,odo_dx,odo_dy,odo_dtheta,sensor_dx,sensor_dy,sensor_dtheta,direction\n";
  const std::string kRow = "0.1,0.01,0,0.02,0.011,0.001,0.02,1\n";
  struct Case {
    const char* name;
    std::string text;
    const char* at;    // "file:line" suffix after the file name
    const char* says;  // a part of the reason
  };
  const Case cases[] = {
      {"empty", "", ":1", "header"},
      {"no_header", kRow, ":1", "header"},
      {"unknown_column", "# interval_s,sensor_dx,sensor_dy,sensor_dtheta,speed\n0.1,0,0,0,1\n", ":1", "speed"},
      {"twice", "# interval_s,sensor_dx,sensor_dy,sensor_dtheta,sensor_dx\n", ":1", "twice"},
      {"missing_column", "# interval_s,sensor_dx,sensor_dtheta\n0.1,0,0\n", ":1", "sensor_dy"},
      {"partial_odometry", "# interval_s,odo_dx,sensor_dx,sensor_dy,sensor_dtheta\n", ":1", "odo_dx"},
      {"too_few_values", kHeader + kRow + "0.1,0.01,0,0.02,0.011,0.001,0.02\n", ":3", "found 7"},
      {"too_many_values", kHeader + kRow + kRow + "0.1,0.01,0,0.02,0.011,0.001,0.02,1,5\n", ":4", "found 9"},
      {"not_a_number", kHeader + "# comment\n\n0.1,0.01,0,0.02,abc,0.001,0.02,1\n", ":4", "sensor_dx 'abc'"},
      {"nan", kHeader + kRow + "0.1,0.01,nan,0.02,0.011,0.001,0.02,1\n", ":3", "odo_dy 'nan' is not finite"},
      {"inf", kHeader + "0.1,0.01,0,0.02,0.011,0.001,-inf,1\n", ":2", "sensor_dtheta '-inf' is not finite"},
      {"zero_interval", kHeader + "0,0.01,0,0.02,0.011,0.001,0.02,1\n", ":2", "interval_s must be positive"},
      {"negative_interval", kHeader + kRow + "-0.1,0.01,0,0.02,0.011,0.001,0.02,1\n", ":3", "interval_s"},
      {"bad_direction", kHeader + "0.1,0.01,0,0.02,0.011,0.001,0.02,2\n", ":2", "direction must be"},
      {"fractional_direction", kHeader + "0.1,0.01,0,0.02,0.011,0.001,0.02,0.5\n", ":2", "direction must be"},
  };
  for (const Case& c : cases) {
    const std::string path = (d / (std::string(c.name) + ".csv")).string();
    write(path, c.text);
    size_t n = 7;
    EXPECT_EQ(planarvo_motion_pairs_load(path.c_str(), nullptr, 0, &n), PLANARVO_ERROR_INVALID_INPUT) << c.name;
    EXPECT_TRUE(mentions(std::string(c.name) + ".csv" + c.at)) << c.name << ": " << planarvo_last_error();
    EXPECT_TRUE(mentions(c.says)) << c.name << ": " << planarvo_last_error();
  }
  // A header and no rows; a file that is not there.
  const std::string only_header = (d / "only_header.csv").string();
  write(only_header, kHeader + "# nothing\n");
  size_t n = 0;
  EXPECT_EQ(planarvo_motion_pairs_load(only_header.c_str(), nullptr, 0, &n), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_TRUE(mentions("no motion pairs")) << planarvo_last_error();
  const std::string missing = (d / "missing.csv").string();
  EXPECT_EQ(planarvo_motion_pairs_load(missing.c_str(), nullptr, 0, &n), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_TRUE(mentions("missing.csv")) << planarvo_last_error();
}

TEST(CApiMotionPairsFile, BadArguments) {
  test::ScratchDir d;
  const std::string path = (d / "pairs.csv").string();
  write(path, "# interval_s,sensor_dx,sensor_dy,sensor_dtheta\n1,0.5,0,0.1\n2,0.5,0,0.1\n");
  size_t n = 0;
  EXPECT_EQ(planarvo_motion_pairs_load(nullptr, nullptr, 0, &n), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(mentions("path")) << planarvo_last_error();
  EXPECT_EQ(planarvo_motion_pairs_load("", nullptr, 0, &n), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_motion_pairs_load(path.c_str(), nullptr, 0, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(mentions("count")) << planarvo_last_error();
  planarvo_motion_pair p[2];
  planarvo_motion_pair_init(&p[0]);
  EXPECT_EQ(planarvo_motion_pairs_load(path.c_str(), p, 0, &n), PLANARVO_ERROR_BUFFER_TOO_SMALL);
  EXPECT_EQ(n, 2u);
  EXPECT_EQ(planarvo_motion_pairs_save(nullptr, p, 1), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_motion_pairs_save(path.c_str(), nullptr, 1), PLANARVO_ERROR_INVALID_ARGUMENT);
}

// ---- planarvo_calibrate --------------------------------------------------------------------

// Noise-free motions from known extrinsics: both methods give the truth, from the built-in
// start and from one far off; NULL options are the defaults.
TEST(CApiCalibrateKnownAnswer, NoiseFreeMotionsGiveTheTruth) {
  const auto pairs = simulated_pairs(CalibrationSim{});
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const auto defaults = calibrate(pairs, &o);
  const auto null_options = calibrate(pairs, nullptr);
  EXPECT_EQ(std::memcmp(defaults.value, null_options.value, sizeof defaults.value), 0);
  o.has_initial = 1;
  const double start[4] = {-0.3, 0.2, 0.5, 1.5};  // yaw 95 degrees off
  std::memcpy(o.initial, start, sizeof start);
  const auto far = calibrate(pairs, &o);
  planarvo_calibration_options nh;
  planarvo_calibration_options_init(&nh);
  nh.method = PLANARVO_CALIBRATE_NONHOLONOMIC;
  nh.fix_scale = 1;
  nh.fixed_scale = kTruth[2];
  const auto nonholonomic = calibrate(pairs, &nh);
  for (const auto* r : {&defaults, &far, &nonholonomic}) {
    EXPECT_EQ(r->ok, 1);
    EXPECT_EQ(r->outliers, 0);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(r->value[i], kTruth[static_cast<size_t>(i)], 1e-9) << i;
    EXPECT_NEAR(std::remainder(r->value[3] - kTruth[3], 2 * M_PI), 0.0, 1e-9);
  }
  EXPECT_EQ(nonholonomic.estimated[2], 0);  // the scale was held
  EXPECT_EQ(nonholonomic.value[2], kTruth[2]);
}

// The library writes a motion-pair calibration's extrinsics.yaml: the graph's x, y, scale, yaw at
// x, y, z, yaw with their covariance; a metric sensor's scale is not a height (z 0, not estimated);
// roll and pitch 0, not estimated; the method's sentence; the notes given.
TEST(CApiCalibrateKnownAnswer, SavedExtrinsicsAreTheGraphsFourParameters) {
  CalibrationSim sim;
  sim.seed = 5;
  sim.sensor_sigma_t = 0.002 / kTruth[2];
  const auto pairs = simulated_pairs(sim);
  const planarvo_calibration_result r = calibrate(pairs, nullptr);
  ASSERT_EQ(r.ok, 1);
  test::ScratchDir dir;
  for (int metric = 0; metric < 2; ++metric) {
    const std::string path = (dir / ("e" + std::to_string(metric) + ".yaml")).string();
    ASSERT_EQ(planarvo_calibration_save(path.c_str(), &r, PLANARVO_CALIBRATE_ODOMETRY, metric, "pairs"), PLANARVO_OK)
        << planarvo_last_error();
    const ExtrinsicsEstimate e = io::read_extrinsics_yaml(path);
    const int at[4] = {0, 1, 2, 5};  // x y scale yaw in x y z roll pitch yaw
    EXPECT_EQ(e.value.x, r.value[0]);
    EXPECT_EQ(e.value.y, r.value[1]);
    EXPECT_EQ(e.value.z, metric ? 0.0 : r.value[2]);
    EXPECT_EQ(e.value.yaw, r.value[3]);
    EXPECT_EQ(e.value.roll, 0.0);
    EXPECT_EQ(e.value.pitch, 0.0);
    for (int i = 0; i < 4; ++i) {
      const bool kept = !(metric && i == 2);
      EXPECT_EQ(e.estimated[static_cast<size_t>(at[i])], kept && r.estimated[i]) << i;
      for (int j = 0; j < 4; ++j)
        EXPECT_EQ(e.covariance(at[i], at[j]), kept && !(metric && j == 2) ? r.covariance[i * 4 + j] : 0.0) << i << j;
    }
    EXPECT_FALSE(e.estimated[3] || e.estimated[4]);
    EXPECT_EQ(e.covariance.row(3).norm() + e.covariance.row(4).norm(), 0.0);
    EXPECT_EQ(e.method, graph::describe_method(graph::CalibrationMethod::Odometry));
    EXPECT_EQ(e.notes, "pairs");
  }
  EXPECT_EQ(planarvo_calibration_save((dir / "x.yaml").string().c_str(), &r,
                                      static_cast<planarvo_calibration_method>(7), 0, nullptr),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  // The parameters' names, in the order of every array.
  for (int i = 0; i < 6; ++i) EXPECT_STREQ(planarvo_extrinsics_name(i), kExtrinsicsNames[static_cast<size_t>(i)]);
  EXPECT_EQ(planarvo_extrinsics_name(-1), nullptr);
  EXPECT_EQ(planarvo_extrinsics_name(6), nullptr);
}

// 2 mm / 2 mrad of noise on both motions, which carry their covariances, and 2 % gross errors.
CalibrationSim noisy_with_gross_errors() {
  CalibrationSim sim;
  sim.seed = 21;
  sim.sensor_sigma_t = 0.002 / kTruth[2];
  sim.sensor_sigma_theta = 0.002;
  sim.odometry_sigma_t = 0.002;
  sim.odometry_sigma_theta = 0.002;
  sim.outlier_fraction = 0.02;
  return sim;
}

// Noisy motions with gross errors: the truth within 4 reported standard deviations, the gross
// errors rejected.
TEST(CApiCalibrateKnownAnswer, NoisyMotionsGiveTheTruthWithinTheReportedSigma) {
  const CalibrationSim sim = noisy_with_gross_errors();
  const auto pairs = simulated_pairs(sim);
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  o.sensor_sigma_relative = o.odometry_sigma_relative = 0.0;
  o.sensor_sigma_floor = o.sensor_sigma_theta = 0.002;
  o.sensor_sigma_floor /= kTruth[2];
  o.odometry_sigma_floor = o.odometry_sigma_theta = 0.002;
  const auto r = calibrate(pairs, &o);
  EXPECT_EQ(r.ok, 1);
  EXPECT_GE(r.outliers, static_cast<int>(0.02 * sim.intervals) - 1);
  for (int i = 0; i < 4; ++i) {
    const double sd = std::sqrt(r.covariance[i * 5]);
    EXPECT_GT(sd, 0.0) << i;
    EXPECT_LT(std::abs(std::remainder(r.value[i] - kTruth[static_cast<size_t>(i)], 2 * M_PI)), 4 * sd) << i;
  }
}

// What plots draw, from the library: each pair's residual at the estimate, whose chi2 over the
// pairs the final solve kept is the solver's own chi2 (the robot's motion eliminated exactly,
// pair_residuals.h), the gated pairs flagged as the result counts them, and the odometry's noise
// model, fitted only when asked.
TEST(CApiCalibrateKnownAnswer, ResidualsAreThePairsShareOfTheFinalChi2) {
  const CalibrationSim sim = noisy_with_gross_errors();
  const auto pairs = simulated_pairs(sim);
  planarvo_calibration_result r{};
  r.struct_size = sizeof r;
  std::vector<planarvo_pair_residual> res(pairs.size());
  planarvo_odometry_noise noise{};
  ASSERT_EQ(planarvo_calibrate_residuals(pairs.data(), pairs.size(), nullptr, &r, res.data(), &noise), PLANARVO_OK)
      << planarvo_last_error();
  const planarvo_calibration_result plain = calibrate(pairs, nullptr);
  EXPECT_EQ(std::memcmp(plain.value, r.value, sizeof r.value), 0);  // the same calibration
  double chi2 = 0.0;
  int outliers = 0;
  for (const planarvo_pair_residual& p : res) {
    ASSERT_EQ(p.has_odometry, 1);
    outliers += p.outlier;
    if (!p.outlier) chi2 += p.chi2;
  }
  EXPECT_EQ(outliers, r.outliers);
  EXPECT_GT(outliers, 0);
  EXPECT_NEAR(chi2, r.summary.final_chi2, 1e-6 * r.summary.final_chi2);
  EXPECT_EQ(noise.fitted, 0);  // the pairs carry their covariances

  // Odometry without covariances, its model fitted to the residuals when asked.
  CalibrationSim bare = sim;
  bare.odometry_sigma_t = bare.odometry_sigma_theta = 0.0;
  bare.outlier_fraction = 0.0;
  const auto bare_pairs = simulated_pairs(bare);
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  for (int fit = 0; fit < 2; ++fit) {
    o.estimate_odometry_noise = fit;
    planarvo_calibration_result rb{};
    rb.struct_size = sizeof rb;
    planarvo_odometry_noise nb{};
    ASSERT_EQ(planarvo_calibrate_residuals(bare_pairs.data(), bare_pairs.size(), &o, &rb, nullptr, &nb), PLANARVO_OK)
        << planarvo_last_error();
    EXPECT_EQ(nb.fitted, fit);
  }
}

// Drives that do not determine the answer: PLANARVO_ERROR_FAILED, the reason as the message and
// in the result, the result filled in.
TEST(CApiCalibrateKnownAnswer, UnobservableDrivesAreFailedWithTheReason) {
  for (const test::Drive drive : {test::Drive::StraightOnly, test::Drive::OneCircle}) {
    CalibrationSim sim;
    sim.drive = drive;
    const auto r = calibrate(simulated_pairs(sim), nullptr, PLANARVO_ERROR_FAILED);
    EXPECT_EQ(r.ok, 0);
    EXPECT_EQ(r.observable[0], 0);
    EXPECT_NE(r.unobservable_reason[0], '\0');
    EXPECT_STREQ(planarvo_last_error(), r.unobservable_reason);
  }
}

TEST(CApiCalibrateArguments, BadArgumentsAreStatusesNamingTheField) {
  const auto pairs = simulated_pairs(CalibrationSim{});
  planarvo_calibration_result r;
  std::memset(&r, 0, sizeof r);
  r.struct_size = sizeof r;
  EXPECT_EQ(planarvo_calibrate(pairs.data(), pairs.size(), nullptr, nullptr), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(mentions("result is NULL")) << planarvo_last_error();
  EXPECT_EQ(planarvo_calibrate(nullptr, pairs.size(), nullptr, &r), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(mentions("no motion pairs")) << planarvo_last_error();
  EXPECT_EQ(planarvo_calibrate(pairs.data(), 0, nullptr, &r), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(mentions("no motion pairs")) << planarvo_last_error();
  planarvo_calibration_result unsized = r;
  unsized.struct_size = 0;
  EXPECT_EQ(planarvo_calibrate(pairs.data(), pairs.size(), nullptr, &unsized), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(mentions("planarvo_calibration_result.struct_size")) << planarvo_last_error();
  auto unsized_pairs = pairs;
  unsized_pairs[0].struct_size = 0;
  EXPECT_EQ(planarvo_calibrate(unsized_pairs.data(), pairs.size(), nullptr, &r), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_TRUE(mentions("planarvo_motion_pair.struct_size")) << planarvo_last_error();

  struct Bad {
    const char* field;
    void (*set)(planarvo_calibration_options*);
  };
  const Bad bad[] = {
      {"planarvo_calibration_options.struct_size", [](planarvo_calibration_options* o) { o->struct_size = 0; }},
      {"planarvo_calibration_options.method",
       [](planarvo_calibration_options* o) { set_enum(&o->method, 2); }},
      {"planarvo_calibration_options.method",
       [](planarvo_calibration_options* o) { set_enum(&o->method, -1); }},
      {"max_iterations", [](planarvo_calibration_options* o) { o->max_iterations = 0; }},
      {"max_iterations", [](planarvo_calibration_options* o) { o->max_iterations = -5; }},
      {"fixed_scale", [](planarvo_calibration_options* o) { o->fix_scale = 1, o->fixed_scale = 0; }},
      {"fixed_scale", [](planarvo_calibration_options* o) { o->fix_scale = 1, o->fixed_scale = -0.2; }},
      {"fixed_scale", [](planarvo_calibration_options* o) { o->fix_scale = 1, o->fixed_scale = std::nan(""); }},
      {"fixed_scale", [](planarvo_calibration_options* o) { o->fix_scale = 1, o->fixed_scale = HUGE_VAL; }},
      {"loss", [](planarvo_calibration_options* o) { set_enum(&o->loss, -1); }},
  };
  for (const Bad& b : bad) {
    planarvo_calibration_options o;
    planarvo_calibration_options_init(&o);
    b.set(&o);
    EXPECT_EQ(planarvo_calibrate(pairs.data(), pairs.size(), &o, &r), PLANARVO_ERROR_INVALID_ARGUMENT) << b.field;
    EXPECT_TRUE(mentions(b.field)) << b.field << ": " << planarvo_last_error();
  }
}

}  // namespace
}  // namespace planarvo
