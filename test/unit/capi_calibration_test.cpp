// The calibration through the C API (planarvo_motion_pairs_load, planarvo_calibrate) against
// independent references: the values written to a CSV file, the true z of simulated motions, and
// graph::calibrate on the same samples (the C API must only translate); versioned motion-pair
// arrays of an older, shorter struct, and per-sample covariances.
#include <cmath>
#include <cstddef>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "common/test_util.h"
#include "graph/calibration/calibration.h"
#include "planarvo/planarvo.h"
#include "unit/graph_calibration_sim.h"

namespace planarvo {
namespace {

using graph::CalibrationOptions;
using graph::CalibrationResult;
using graph::MotionSample;
using test::CalibrationSim;

// The paper's camera configuration 1 (conventions.md): x, y, scale (height), yaw.
const std::array<double, 4> kTruth = {0.2441, -0.0185, 0.1787, -9.2 * M_PI / 180};

// planarvo_motion_pair as the first versioned header declared it (up to direction).
struct MotionPairV1 {
  size_t struct_size;
  double interval;
  planarvo_se2 sensor;
  int32_t has_odometry;
  planarvo_se2 odometry;
  int32_t has_direction;
  int32_t direction;
};
static_assert(offsetof(MotionPairV1, direction) == offsetof(planarvo_motion_pair, direction));

void to_c(const Eigen::Matrix3d& m, double* out) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[r * 3 + c] = m(r, c);
}

// The samples as C motion pairs, field by field.
std::vector<planarvo_motion_pair> to_pairs(const std::vector<MotionSample>& samples) {
  std::vector<planarvo_motion_pair> pairs(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    const MotionSample& s = samples[i];
    planarvo_motion_pair& p = pairs[i];
    planarvo_motion_pair_init(&p);
    p.interval = s.interval;
    p.sensor = {s.sensor.value.x, s.sensor.value.y, s.sensor.value.theta};
    if (s.sensor.has_covariance()) {
      p.has_sensor_covariance = 1;
      to_c(s.sensor.covariance, p.sensor_covariance);
    }
    if (s.odometry) {
      p.has_odometry = 1;
      p.odometry = {s.odometry->value.x, s.odometry->value.y, s.odometry->value.theta};
      if (s.odometry->has_covariance()) {
        p.has_odometry_covariance = 1;
        to_c(s.odometry->covariance, p.odometry_covariance);
      }
    }
    if (s.direction) {
      p.has_direction = 1;
      p.direction = *s.direction;
    }
  }
  return pairs;
}

planarvo_calibration_result calibrate_c(const planarvo_motion_pair* pairs, size_t n,
                                        const planarvo_calibration_options& o,
                                        planarvo_status expected = PLANARVO_OK) {
  planarvo_calibration_result r;
  std::memset(&r, 0, sizeof r);
  r.struct_size = sizeof r;
  EXPECT_EQ(planarvo_calibrate(pairs, n, &o, &r), expected) << planarvo_last_error();
  return r;
}

planarvo_calibration_options metric_options() {
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  o.fix_scale = 1;
  o.fixed_scale = kTruth[2];
  return o;
}

CalibrationOptions graph_options(const planarvo_calibration_options& o) {
  CalibrationOptions g;
  g.method = o.method == PLANARVO_CALIBRATE_ODOMETRY ? graph::CalibrationMethod::Odometry
                                                     : graph::CalibrationMethod::Nonholonomic;
  g.fix_scale = o.fix_scale != 0;
  g.fixed_scale = o.fixed_scale;
  g.sensor_sigma_relative = o.sensor_sigma_relative;
  g.sensor_sigma_floor = o.sensor_sigma_floor;
  g.sensor_sigma_theta = o.sensor_sigma_theta;
  g.odometry_sigma_relative = o.odometry_sigma_relative;
  g.odometry_sigma_floor = o.odometry_sigma_floor;
  g.odometry_sigma_theta = o.odometry_sigma_theta;
  const graph::RobustLoss losses[4] = {graph::RobustLoss::None, graph::RobustLoss::Huber, graph::RobustLoss::Cauchy,
                                       graph::RobustLoss::Tukey};
  g.loss = losses[o.loss];
  g.loss_scale = o.loss_scale;
  g.gate_sigma = o.gate_sigma;
  g.still_speed = o.still_speed;
  return g;
}

// Equal to 1e-12 (relative for the covariance), and the same flags.
void expect_same(const planarvo_calibration_result& c, const CalibrationResult& g) {
  for (int i = 0; i < 4; ++i) {
    const auto k = static_cast<size_t>(i);
    EXPECT_NEAR(c.value[i], g.value[k], 1e-12) << i;
    EXPECT_EQ(c.estimated[i] != 0, g.estimated[k]) << i;
    EXPECT_EQ(c.observable[i] != 0, g.observable[k]) << i;
    for (int j = 0; j < 4; ++j) {
      const double a = c.covariance[i * 4 + j], b = g.covariance(i, j);
      if (std::isfinite(b))
        EXPECT_NEAR(a, b, 1e-12 * std::max(1e-300, std::abs(b))) << i << "," << j;
      else
        EXPECT_EQ(a, b) << i << "," << j;
    }
  }
  EXPECT_EQ(c.outliers, g.outliers);
  EXPECT_EQ(c.ambiguous != 0, g.ambiguous);
  EXPECT_EQ(c.ok != 0, g.ok());
  EXPECT_EQ(c.summary.iterations, g.summary.num_iterations);
  EXPECT_STREQ(c.unobservable_reason, g.unobservable_reason.c_str());
  EXPECT_EQ(c.total_iterations, g.total_iterations);
  EXPECT_NEAR(c.variance_factor, g.variance_factor, 1e-12 * g.variance_factor);
}

bool same_values(const planarvo_calibration_result& a, const planarvo_calibration_result& b) {
  return std::memcmp(a.value, b.value, sizeof a.value) == 0 &&
         std::memcmp(a.covariance, b.covariance, sizeof a.covariance) == 0 && a.outliers == b.outliers;
}

CalibrationSim noisy_sim(unsigned seed) {
  CalibrationSim sim;
  sim.intervals = 150;
  sim.seed = seed;
  sim.sensor_sigma_t = 0.003 / kTruth[2];
  sim.sensor_sigma_theta = 0.003;
  sim.odometry_sigma_t = 0.003;
  sim.odometry_sigma_theta = 0.003;
  sim.outlier_fraction = 0.03;
  return sim;
}

// Drops the covariances the simulation attaches, so that the options' noise model is used.
std::vector<MotionSample> without_covariances(std::vector<MotionSample> samples) {
  for (MotionSample& s : samples) {
    s.sensor.covariance.setZero();
    if (s.odometry) s.odometry->covariance.setZero();
  }
  return samples;
}

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(CApiMotionPairs, LoadReadsTheFileValues) {
  test::ScratchDir d;
  const std::string path = (d / "pairs.csv").string();
  write(path, "# interval_s, odo_dx, odo_dy, odo_dtheta, sensor_dx, sensor_dy, sensor_dtheta, direction\n"
              "0.5, 0.1, -0.002, 0.25, 0.125, 0.0625, 0.2501, 1\n"
              "0.25, -0.05, 0, -0.5, -1e-17, 3.5, -0.4999, -1\n"
              "1, 0, 0, 1.5, 0.01, -0.02, 1.5, 0\n");
  size_t n = 0;
  ASSERT_EQ(planarvo_motion_pairs_load(path.c_str(), nullptr, 0, &n), PLANARVO_OK);
  ASSERT_EQ(n, 3u);
  std::vector<planarvo_motion_pair> pairs(n);
  std::memset(pairs.data(), 0x5a, n * sizeof pairs[0]);  // every byte must be written
  pairs[0].struct_size = sizeof(planarvo_motion_pair);
  size_t m = 0;
  ASSERT_EQ(planarvo_motion_pairs_load(path.c_str(), pairs.data(), 2, &m), PLANARVO_ERROR_BUFFER_TOO_SMALL);
  EXPECT_EQ(m, 3u);
  ASSERT_EQ(planarvo_motion_pairs_load(path.c_str(), pairs.data(), n, &m), PLANARVO_OK) << planarvo_last_error();
  const double expected[3][8] = {{0.5, 0.1, -0.002, 0.25, 0.125, 0.0625, 0.2501, 1},
                                 {0.25, -0.05, 0, -0.5, -1e-17, 3.5, -0.4999, -1},
                                 {1, 0, 0, 1.5, 0.01, -0.02, 1.5, 0}};
  for (size_t i = 0; i < n; ++i) {
    const planarvo_motion_pair& p = pairs[i];
    const double* e = expected[i];
    EXPECT_EQ(p.struct_size, sizeof(planarvo_motion_pair)) << i;
    EXPECT_EQ(p.interval, e[0]) << i;
    EXPECT_EQ(p.has_odometry, 1) << i;
    EXPECT_EQ(p.odometry.x, e[1]) << i;
    EXPECT_EQ(p.odometry.y, e[2]) << i;
    EXPECT_EQ(p.odometry.theta, e[3]) << i;
    EXPECT_EQ(p.sensor.x, e[4]) << i;
    EXPECT_EQ(p.sensor.y, e[5]) << i;
    EXPECT_EQ(p.sensor.theta, e[6]) << i;
    EXPECT_EQ(p.has_direction, 1) << i;
    EXPECT_EQ(p.direction, static_cast<int32_t>(e[7])) << i;
    EXPECT_EQ(p.has_sensor_covariance, 0) << i;
    EXPECT_EQ(p.has_odometry_covariance, 0) << i;
    for (int k = 0; k < 9; ++k) {
      EXPECT_EQ(p.sensor_covariance[k], 0.0) << i;
      EXPECT_EQ(p.odometry_covariance[k], 0.0) << i;
    }
  }
}

TEST(CApiMotionPairs, LoadWithoutOdometryOrDirection) {
  test::ScratchDir d;
  const std::string path = (d / "pairs.csv").string();
  write(path, "# sensor_dtheta, interval_s, sensor_dx, sensor_dy\n0.75, 2, 0.5, -0.25\n");
  planarvo_motion_pair p;
  planarvo_motion_pair_init(&p);
  size_t n = 0;
  ASSERT_EQ(planarvo_motion_pairs_load(path.c_str(), &p, 1, &n), PLANARVO_OK) << planarvo_last_error();
  ASSERT_EQ(n, 1u);
  EXPECT_EQ(p.interval, 2.0);
  EXPECT_EQ(p.sensor.x, 0.5);
  EXPECT_EQ(p.sensor.y, -0.25);
  EXPECT_EQ(p.sensor.theta, 0.75);
  EXPECT_EQ(p.has_odometry, 0);
  EXPECT_EQ(p.has_direction, 0);
}

TEST(CApiMotionPairs, LoadWritesAnOlderStructAtItsStride) {
  test::ScratchDir d;
  const std::string path = (d / "pairs.csv").string();
  write(path, "# interval_s, sensor_dx, sensor_dy, sensor_dtheta, direction\n1, 0.5, 0, 0, 1\n2, -0.5, 0, 0.5, -1\n");
  std::vector<MotionPairV1> v1(3);
  std::memset(v1.data(), 0x5a, sizeof(MotionPairV1) * v1.size());  // v1[2] must stay untouched
  v1[0].struct_size = sizeof(MotionPairV1);
  size_t n = 0;
  ASSERT_EQ(planarvo_motion_pairs_load(path.c_str(), reinterpret_cast<planarvo_motion_pair*>(v1.data()), 2, &n),
            PLANARVO_OK)
      << planarvo_last_error();
  ASSERT_EQ(n, 2u);
  EXPECT_EQ(v1[1].struct_size, sizeof(MotionPairV1));
  EXPECT_EQ(v1[0].interval, 1.0);
  EXPECT_EQ(v1[0].sensor.x, 0.5);
  EXPECT_EQ(v1[1].interval, 2.0);
  EXPECT_EQ(v1[1].sensor.x, -0.5);
  EXPECT_EQ(v1[1].sensor.theta, 0.5);
  EXPECT_EQ(v1[1].direction, -1);
  const std::vector<unsigned char> untouched(sizeof(MotionPairV1), 0x5a);
  EXPECT_EQ(std::memcmp(&v1[2], untouched.data(), sizeof(MotionPairV1)), 0);

  v1[0].struct_size = 0;  // the stride must be given
  EXPECT_EQ(planarvo_motion_pairs_load(path.c_str(), reinterpret_cast<planarvo_motion_pair*>(v1.data()), 2, &n),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("struct_size"), std::string::npos) << planarvo_last_error();
}

TEST(CApiCalibrate, EqualsGraphCalibrateOnTheSameSamples) {
  const auto samples = without_covariances(test::simulate_motions(kTruth, noisy_sim(3)).samples);
  const auto pairs = to_pairs(samples);
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const auto c = calibrate_c(pairs.data(), pairs.size(), o);
  const CalibrationResult g = graph::calibrate(samples, graph_options(o));
  EXPECT_GT(g.outliers, 0);
  expect_same(c, g);

  // The nonholonomic method, labels given, odometry absent.
  auto sim = noisy_sim(4);
  sim.odometry = false;
  const auto nh = without_covariances(test::simulate_motions(kTruth, sim).samples);
  planarvo_calibration_options on = metric_options();
  on.method = PLANARVO_CALIBRATE_NONHOLONOMIC;
  expect_same(calibrate_c(to_pairs(nh).data(), nh.size(), on), graph::calibrate(nh, graph_options(on)));
}

TEST(CApiCalibrate, NoiseFreeMotionsGiveTheTruth) {
  const auto samples = test::simulate_motions(kTruth, CalibrationSim{}).samples;
  const auto pairs = to_pairs(samples);
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const auto c = calibrate_c(pairs.data(), pairs.size(), o);
  EXPECT_EQ(c.ok, 1);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(c.value[i], kTruth[static_cast<size_t>(i)], 1e-9) << i;
  EXPECT_NEAR(wrap_angle(c.value[3] - kTruth[3]), 0.0, 1e-9);
  EXPECT_EQ(c.outliers, 0);
}

TEST(CApiCalibrate, AnOlderShorterPairStructCalibratesIdentically) {
  const auto samples = without_covariances(test::simulate_motions(kTruth, noisy_sim(5)).samples);
  const auto pairs = to_pairs(samples);
  std::vector<MotionPairV1> v1(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    std::memcpy(&v1[i], &pairs[i], sizeof(MotionPairV1));
    v1[i].struct_size = sizeof(MotionPairV1);
  }
  // And a newer, longer one: what follows the known fields is not read.
  struct MotionPairNext {
    planarvo_motion_pair known;
    double unknown[3];
  };
  std::vector<MotionPairNext> next(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    next[i].known = pairs[i];
    next[i].known.struct_size = sizeof(MotionPairNext);
    next[i].unknown[0] = next[i].unknown[1] = next[i].unknown[2] = std::nan("");
  }
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const auto full = calibrate_c(pairs.data(), pairs.size(), o);
  const auto old = calibrate_c(reinterpret_cast<const planarvo_motion_pair*>(v1.data()), v1.size(), o);
  const auto later = calibrate_c(reinterpret_cast<const planarvo_motion_pair*>(next.data()), next.size(), o);
  EXPECT_TRUE(same_values(full, old));
  EXPECT_TRUE(same_values(full, later));
  expect_same(old, graph::calibrate(samples, graph_options(o)));

  // Smaller than the first version: refused, naming the field.
  for (auto& p : v1) p.struct_size = offsetof(MotionPairV1, direction);
  calibrate_c(reinterpret_cast<const planarvo_motion_pair*>(v1.data()), v1.size(), o, PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("planarvo_motion_pair.struct_size"), std::string::npos)
      << planarvo_last_error();
  // Elements of different sizes: the stride would be wrong.
  auto mixed = pairs;
  mixed[7].struct_size = sizeof(MotionPairV1);
  calibrate_c(mixed.data(), mixed.size(), o, PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("pairs[7].struct_size"), std::string::npos)
      << planarvo_last_error();
}

TEST(CApiCalibrate, PerSampleCovariancesActAsInGraphCalibrate) {
  // Full, anisotropic covariances of the right perturbation, different per sample.
  auto samples = test::simulate_motions(kTruth, noisy_sim(6)).samples;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_covariance = [&](double sigma_t, double sigma_theta) {
    Eigen::Matrix3d L = Eigen::Matrix3d::Zero();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c <= r; ++c) L(r, c) = (r == c ? 1.0 + 0.5 * u(rng) : 0.3 * u(rng));
    const Eigen::Vector3d s(sigma_t, sigma_t, sigma_theta);
    return Eigen::Matrix3d(s.asDiagonal() * L * L.transpose() * s.asDiagonal());
  };
  for (MotionSample& s : samples) {
    s.sensor.covariance = random_covariance(0.003 / kTruth[2], 0.003);
    s.odometry->covariance = random_covariance(0.003, 0.003);
  }
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const auto with = calibrate_c(to_pairs(samples).data(), samples.size(), o);
  expect_same(with, graph::calibrate(samples, graph_options(o)));
  const auto plain = without_covariances(samples);
  const auto without = calibrate_c(to_pairs(plain).data(), plain.size(), o);
  expect_same(without, graph::calibrate(plain, graph_options(o)));
  double moved = 0.0;
  for (int i = 0; i < 4; ++i) moved = std::max(moved, std::abs(with.value[i] - without.value[i]));
  EXPECT_GT(moved, 1e-5);

  // Only the sensor's or only the odometry's.
  auto sensor_only = samples;
  for (MotionSample& s : sensor_only) s.odometry->covariance.setZero();
  expect_same(calibrate_c(to_pairs(sensor_only).data(), samples.size(), o),
              graph::calibrate(sensor_only, graph_options(o)));
  auto odometry_only = samples;
  for (MotionSample& s : odometry_only) s.sensor.covariance.setZero();
  expect_same(calibrate_c(to_pairs(odometry_only).data(), samples.size(), o),
              graph::calibrate(odometry_only, graph_options(o)));
}

TEST(CApiCalibrate, RejectsUnusablePairs) {
  const auto samples = test::simulate_motions(kTruth, CalibrationSim{}).samples;
  const auto good = to_pairs(samples);
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  auto expect_rejected = [&](std::vector<planarvo_motion_pair> pairs, const std::string& mention) {
    calibrate_c(pairs.data(), pairs.size(), o, PLANARVO_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(std::string(planarvo_last_error()).find(mention), std::string::npos) << planarvo_last_error();
  };
  auto p = good;
  p[2].has_sensor_covariance = 1;  // all zero
  expect_rejected(p, "pairs[2].sensor_covariance");
  p = good;
  p[3].has_odometry_covariance = 1;
  p[3].odometry_covariance[0] = p[3].odometry_covariance[4] = p[3].odometry_covariance[8] = 1e-4;
  p[3].has_odometry = 0;
  expect_rejected(p, "pairs[3]");
  p = good;
  p[4].has_sensor_covariance = 1;
  p[4].sensor_covariance[0] = -1.0;  // not positive definite
  expect_rejected(p, "sensor covariance");
  p = good;
  p[5].has_sensor_covariance = 1;
  p[5].sensor_covariance[4] = std::nan("");
  expect_rejected(p, "pairs[5].sensor_covariance is not finite");
  p = good;
  p[6].direction = 2;
  expect_rejected(p, "pairs[6].direction");
}

TEST(CApiCalibrationOptions, InitTakesTheGraphDefaults) {
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const CalibrationOptions d;
  EXPECT_EQ(o.struct_size, sizeof o);
  EXPECT_EQ(o.sensor_sigma_relative, d.sensor_sigma_relative);
  EXPECT_EQ(o.sensor_sigma_floor, d.sensor_sigma_floor);
  EXPECT_EQ(o.sensor_sigma_theta, d.sensor_sigma_theta);
  EXPECT_EQ(o.odometry_sigma_relative, d.odometry_sigma_relative);
  EXPECT_EQ(o.odometry_sigma_floor, d.odometry_sigma_floor);
  EXPECT_EQ(o.odometry_sigma_theta, d.odometry_sigma_theta);
  EXPECT_EQ(o.loss, PLANARVO_ROBUST_LOSS_CAUCHY);
  EXPECT_EQ(d.loss, graph::RobustLoss::Cauchy);
  EXPECT_EQ(o.loss_scale, d.loss_scale);
  EXPECT_EQ(o.gate_sigma, d.gate_sigma);
  EXPECT_EQ(o.still_speed, d.still_speed);
}

// Each noise-model option changes the result, and exactly as it changes graph::calibrate's.
TEST(CApiCalibrationOptions, NoiseModelReachesTheSolver) {
  const auto samples = without_covariances(test::simulate_motions(kTruth, noisy_sim(8)).samples);
  const auto pairs = to_pairs(samples);
  planarvo_calibration_options d;
  planarvo_calibration_options_init(&d);
  const auto base = calibrate_c(pairs.data(), pairs.size(), d);
  EXPECT_GT(base.outliers, 0);
  struct Variant {
    const char* name;
    void (*set)(planarvo_calibration_options*);
  };
  const Variant variants[] = {
      {"sensor_sigma_relative", [](planarvo_calibration_options* o) { o->sensor_sigma_relative = 0.03; }},
      {"sensor_sigma_floor", [](planarvo_calibration_options* o) { o->sensor_sigma_floor = 0.01; }},
      {"sensor_sigma_theta", [](planarvo_calibration_options* o) { o->sensor_sigma_theta = 0.01; }},
      {"odometry_sigma_relative", [](planarvo_calibration_options* o) { o->odometry_sigma_relative = 0.03; }},
      {"odometry_sigma_floor", [](planarvo_calibration_options* o) { o->odometry_sigma_floor = 0.003; }},
      {"odometry_sigma_theta", [](planarvo_calibration_options* o) { o->odometry_sigma_theta = 0.01; }},
      {"loss none", [](planarvo_calibration_options* o) { o->loss = PLANARVO_ROBUST_LOSS_NONE; }},
      {"loss huber", [](planarvo_calibration_options* o) { o->loss = PLANARVO_ROBUST_LOSS_HUBER; }},
      {"loss tukey", [](planarvo_calibration_options* o) { o->loss = PLANARVO_ROBUST_LOSS_TUKEY; }},
      {"loss_scale", [](planarvo_calibration_options* o) { o->loss_scale = 1.0; }},
      {"gate_sigma 3", [](planarvo_calibration_options* o) { o->gate_sigma = 3.0; }},
      {"gate_sigma 0", [](planarvo_calibration_options* o) { o->gate_sigma = 0.0; }},
  };
  for (const Variant& v : variants) {
    planarvo_calibration_options o = d;
    v.set(&o);
    const auto c = calibrate_c(pairs.data(), pairs.size(), o);
    SCOPED_TRACE(v.name);
    expect_same(c, graph::calibrate(samples, graph_options(o)));
    EXPECT_FALSE(same_values(c, base));
  }
  // Gating on (5) and off (0): the gross errors are dropped, or only down-weighted.
  planarvo_calibration_options no_gate = d;
  no_gate.gate_sigma = 0.0;
  EXPECT_EQ(calibrate_c(pairs.data(), pairs.size(), no_gate).outliers, 0);
}

// still_speed labels the intervals that carry odometry but no label: at 0, turning in place
// (odometry's forward motion exactly 0) counts as backwards, which moves y.
TEST(CApiCalibrationOptions, StillSpeedLabelsFromOdometry) {
  CalibrationSim sim;
  sim.sensor_sigma_t = 0.003 / kTruth[2];
  sim.sensor_sigma_theta = 0.003;
  sim.labels = false;
  const auto samples = without_covariances(test::simulate_motions(kTruth, sim).samples);
  const auto pairs = to_pairs(samples);
  planarvo_calibration_options o = metric_options();
  o.method = PLANARVO_CALIBRATE_NONHOLONOMIC;
  const auto labelled = calibrate_c(pairs.data(), pairs.size(), o);
  expect_same(labelled, graph::calibrate(samples, graph_options(o)));
  EXPECT_NEAR(labelled.value[1], kTruth[1], 0.002);
  o.still_speed = 0.0;
  const auto zero = calibrate_c(pairs.data(), pairs.size(), o, PLANARVO_ERROR_FAILED);
  expect_same(zero, graph::calibrate(samples, graph_options(o)));
  EXPECT_NE(zero.value[1], labelled.value[1]);
}

TEST(CApiCalibrationOptions, AnOlderOptionsStructTakesTheDefaults) {
  const auto samples = without_covariances(test::simulate_motions(kTruth, noisy_sim(9)).samples);
  const auto pairs = to_pairs(samples);
  planarvo_calibration_options d;
  planarvo_calibration_options_init(&d);
  const auto base = calibrate_c(pairs.data(), pairs.size(), d);
  planarvo_calibration_options old = d;
  old.struct_size = offsetof(planarvo_calibration_options, log_user_data) + sizeof(void*);
  old.sensor_sigma_theta = -1.0;  // beyond the caller's struct: never read
  old.gate_sigma = std::nan("");
  old.loss = static_cast<planarvo_robust_loss>(99);
  EXPECT_TRUE(same_values(calibrate_c(pairs.data(), pairs.size(), old), base));
}

TEST(CApiCalibrationOptions, InvalidNoiseModelNamesTheField) {
  const auto samples = test::simulate_motions(kTruth, CalibrationSim{}).samples;
  const auto pairs = to_pairs(samples);
  planarvo_calibration_options d;
  planarvo_calibration_options_init(&d);
  auto expect_rejected = [&](const planarvo_calibration_options& o, const std::string& message) {
    calibrate_c(pairs.data(), pairs.size(), o, PLANARVO_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(std::string(planarvo_last_error()).find(message), std::string::npos) << planarvo_last_error();
  };
  double planarvo_calibration_options::*const non_negative[] = {
      &planarvo_calibration_options::sensor_sigma_relative, &planarvo_calibration_options::sensor_sigma_floor,
      &planarvo_calibration_options::odometry_sigma_relative, &planarvo_calibration_options::odometry_sigma_floor,
      &planarvo_calibration_options::gate_sigma, &planarvo_calibration_options::still_speed};
  const char* const non_negative_names[] = {"sensor_sigma_relative",   "sensor_sigma_floor", "odometry_sigma_relative",
                                            "odometry_sigma_floor",    "gate_sigma",         "still_speed"};
  for (size_t i = 0; i < 6; ++i)
    for (double bad : {-1e-9, std::nan(""), HUGE_VAL}) {
      planarvo_calibration_options o = d;
      o.*non_negative[i] = bad;
      expect_rejected(o, std::string("planarvo_calibration_options.") + non_negative_names[i] + " must be >= 0");
    }
  double planarvo_calibration_options::*const positive[] = {&planarvo_calibration_options::sensor_sigma_theta,
                                                            &planarvo_calibration_options::odometry_sigma_theta,
                                                            &planarvo_calibration_options::loss_scale};
  const char* const positive_names[] = {"sensor_sigma_theta", "odometry_sigma_theta", "loss_scale"};
  for (size_t i = 0; i < 3; ++i)
    for (double bad : {0.0, -1.0, std::nan("")}) {
      planarvo_calibration_options o = d;
      o.*positive[i] = bad;
      expect_rejected(o, std::string("planarvo_calibration_options.") + positive_names[i] + " must be > 0");
    }
  planarvo_calibration_options o = d;
  o.sensor_sigma_floor = o.sensor_sigma_relative = 0.0;
  expect_rejected(o, "planarvo_calibration_options.sensor_sigma_floor and sensor_sigma_relative");
  o = d;
  o.odometry_sigma_floor = o.odometry_sigma_relative = 0.0;
  expect_rejected(o, "planarvo_calibration_options.odometry_sigma_floor and odometry_sigma_relative");
  o = d;
  o.loss = static_cast<planarvo_robust_loss>(4);
  expect_rejected(o, "planarvo_calibration_options.loss");
  // Zero floor or relative part alone is a valid model.
  o = d;
  o.sensor_sigma_floor = 0.0;
  o.odometry_sigma_relative = 0.0;
  calibrate_c(pairs.data(), pairs.size(), o);
}

TEST(CApiCalibrationResult, TotalsCoverEverySolve) {
  const auto samples = without_covariances(test::simulate_motions(kTruth, noisy_sim(10)).samples);
  const auto pairs = to_pairs(samples);
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const auto c = calibrate_c(pairs.data(), pairs.size(), o);
  const CalibrationResult g = graph::calibrate(samples, graph_options(o));
  expect_same(c, g);  // total_iterations and variance_factor included
  EXPECT_GT(c.total_iterations, c.summary.iterations);  // a robust pass, then gated ones
  EXPECT_GT(c.variance_factor, 0.0);
  EXPECT_GE(c.total_seconds, c.summary.seconds);
  EXPECT_GT(c.total_seconds, 0.0);
}

TEST(CApiCalibrationResult, AnOlderResultStructIsWrittenNoFurther) {
  const auto samples = test::simulate_motions(kTruth, CalibrationSim{}).samples;
  const auto pairs = to_pairs(samples);
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const size_t first = offsetof(planarvo_calibration_result, summary) + sizeof(planarvo_solver_summary);
  planarvo_calibration_result r;
  std::memset(&r, 0x5a, sizeof r);
  r.struct_size = first;
  ASSERT_EQ(planarvo_calibrate(pairs.data(), pairs.size(), &o, &r), PLANARVO_OK) << planarvo_last_error();
  EXPECT_EQ(r.struct_size, first);
  EXPECT_NEAR(r.value[0], kTruth[0], 1e-9);
  std::vector<unsigned char> tail(sizeof r - first, 0x5a);
  EXPECT_EQ(std::memcmp(reinterpret_cast<const unsigned char*>(&r) + first, tail.data(), tail.size()), 0);
  r.struct_size = first - 1;
  EXPECT_EQ(planarvo_calibrate(pairs.data(), pairs.size(), &o, &r), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("planarvo_calibration_result.struct_size"), std::string::npos);
}

}  // namespace
}  // namespace planarvo
