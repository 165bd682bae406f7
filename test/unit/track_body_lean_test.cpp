// The vehicle's lean fit (track/body_lean.h) against drives made up with a known lean: the slope
// recovered within its standard error's spread over many noisy drives, and exactly without noise.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/se2.h"
#include "track/body_lean.h"

namespace planarvo::track {
namespace {

struct MadeUp {
  std::vector<double> t, roll, pitch;
  std::vector<SE2> motion;
  std::vector<bool> use;
};

// 600 frames at 30 Hz: a yaw rate and a speed that vary smoothly; roll = k_roll * omega(t_k) +
// 0.01 and pitch = k_pitch * a(t_k) - 0.02 at the frames, plus noise of `noise` radians.
MadeUp drive(double k_roll, double k_pitch, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  MadeUp d;
  const double dt = 1.0 / 30.0;
  auto omega = [](double t) { return 0.5 * std::sin(0.7 * t); };
  auto speed = [](double t) { return 2.0 + std::sin(0.4 * t); };
  auto accel = [](double t) { return 0.4 * std::cos(0.4 * t); };
  for (int k = 0; k < 600; ++k) {
    const double t = k * dt;
    d.t.push_back(t);
    // The interval ending at t: its mean velocities (the midpoint's, to second order).
    const double mid = t - 0.5 * dt;
    d.motion.push_back(SE2::exp(Eigen::Vector3d(speed(mid) * dt, 0.0, omega(mid) * dt)));
    d.roll.push_back(k_roll * omega(t) + 0.01 + noise * n01(rng));
    d.pitch.push_back(k_pitch * accel(t) - 0.02 + noise * n01(rng));
    d.use.push_back(k != 300);  // one frame left out
  }
  return d;
}

TEST(BodyLean, ExactWithoutNoise) {
  const MadeUp d = drive(-0.07, 0.03, 0.0, 1);
  const BodyLean f = fit_body_lean(d.t, d.motion, d.roll, d.pitch, d.use);
  EXPECT_NEAR(f.roll_per_yaw_rate.slope, -0.07, 2e-4);
  EXPECT_NEAR(f.roll_per_yaw_rate.offset, 0.01, 1e-4);
  EXPECT_NEAR(f.pitch_per_acceleration.slope, 0.03, 5e-4);
  EXPECT_NEAR(f.pitch_per_acceleration.offset, -0.02, 1e-4);
  EXPECT_GT(f.roll_per_yaw_rate.r2, 0.999);
  EXPECT_EQ(f.roll_per_yaw_rate.samples, 598);  // frames 1..599, less the one left out
}

TEST(BodyLean, SigmaDescribesTheSpreadOverDrives) {
  double z2 = 0;
  const int runs = 200;
  for (int i = 0; i < runs; ++i) {
    const MadeUp d = drive(-0.07, 0.0, 0.002, 100 + static_cast<unsigned>(i));
    const LineFit f = fit_body_lean(d.t, d.motion, d.roll, d.pitch, d.use).roll_per_yaw_rate;
    z2 += std::pow((f.slope + 0.07) / f.slope_sigma, 2);
  }
  const double rms = std::sqrt(z2 / runs);
  EXPECT_GT(rms, 0.8);
  EXPECT_LT(rms, 1.25);
}

TEST(BodyLean, TooFewFramesOrNoTurningSaySo) {
  const LineFit none = fit_line({1.0, 2.0}, {3.0, 4.0});
  EXPECT_EQ(none.samples, 2);
  EXPECT_TRUE(std::isinf(none.slope_sigma));
  const LineFit flat = fit_line({1.0, 1.0, 1.0}, {3.0, 4.0, 5.0});
  EXPECT_TRUE(std::isinf(flat.slope_sigma));
  EXPECT_DOUBLE_EQ(flat.offset, 4.0);
}

}  // namespace
}  // namespace planarvo::track
