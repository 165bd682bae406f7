// Simulated motion samples for the graph calibrations (tests and test/bench/bench_calibration):
// a differential-drive robot driving constant-(v, ω) intervals, its wheel odometry, and the
// motion of a sensor mounted at a known z = (x, y, scale, yaw), m_s = S_1/scale(T⁻¹ · m_r · T)
// (conventions.md), with additive Gaussian noise on the motions' (x, y, θ), gross sensor errors
// on request, and direction labels (the sign of v, 0 for v = 0).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "core/se2.h"
#include "graph/calibration/calibration.h"

namespace planarvo::test {

enum class Drive {
  Rich,           // forwards and backwards, turns both ways, straight, turning in place
  StraightOnly,   // forwards and backwards, no rotation at all
  OneCircle,      // one (v, ω) throughout
  ForwardOnly,    // forwards, turns both ways of radius ≥ v_min / ω_max, no turning in place
  TurnInPlace,    // v = 0 throughout
};

struct CalibrationSim {
  int intervals = 300;
  double dt = 1.0;                         // s per interval
  double speed_min = 0.1, speed_max = 0.4;  // m/s
  double omega_max = 0.8;                  // rad/s
  Drive drive = Drive::Rich;
  // Noise of the motions' (x, y, θ): sensor in sensor units, odometry in metres; radians. When
  // positive, the samples carry the matching covariances.
  double sensor_sigma_t = 0.0, sensor_sigma_theta = 0.0;
  double odometry_sigma_t = 0.0, odometry_sigma_theta = 0.0;
  bool odometry = true, labels = true;
  double outlier_fraction = 0.0, outlier_size = 0.1;  // gross sensor errors, metres
  // Forward speed while "turning in place" (still labelled 0), m/s: labels from a threshold.
  double in_place_speed = 0.0;
  unsigned seed = 1;
};

struct SimulatedMotions {
  std::vector<graph::MotionSample> samples;
  std::vector<SE2> robot;     // true robot motions
  std::vector<int> outliers;  // indices of samples with gross errors
};

inline SimulatedMotions simulate_motions(const std::array<double, 4>& z, const CalibrationSim& o) {
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  const SE2 T(z[0], z[1], z[3]);
  const double scale = z[2];
  SimulatedMotions out;
  const double speed_span = o.speed_max - o.speed_min;
  for (int k = 0; k < o.intervals; ++k) {
    double v = 0.0, w = 0.0;
    const double speed = o.speed_min + speed_span * u(rng);
    const double turn = o.omega_max * (2.0 * u(rng) - 1.0);
    switch (o.drive) {
      case Drive::Rich: {
        const int kind = k % 6;  // 0: in place, 1, 2: forwards, 3, 4: backwards, 5: straight
        const double sign = (k / 6) % 2 ? 1.0 : -1.0;
        if (kind == 0) {
          w = sign * std::max(0.3 * o.omega_max, std::abs(turn));
          v = o.in_place_speed;
        } else if (kind == 5) {
          v = sign * speed;
        } else {
          v = (kind <= 2 ? 1.0 : -1.0) * speed;
          w = turn;
        }
        break;
      }
      case Drive::StraightOnly: v = (k % 2 ? 1.0 : -1.0) * speed; break;
      case Drive::OneCircle: v = 0.5 * (o.speed_min + o.speed_max), w = 0.5 * o.omega_max; break;
      case Drive::ForwardOnly: v = speed, w = turn; break;
      case Drive::TurnInPlace:
        w = (k % 2 ? 1.0 : -1.0) * std::max(0.3 * o.omega_max, std::abs(turn));
        v = o.in_place_speed;
        break;
    }
    const SE2 robot = SE2::exp(Eigen::Vector3d(v, 0.0, w) * o.dt);
    const SE2 metric = T.inverse() * robot * T;
    graph::MotionSample s;
    s.interval = o.dt;
    // The noises drawn theta, y, x: the order GCC evaluated SE2(...)'s arguments in when they
    // were drawn there (unspecified in C++: clang drew other data sets), so the data are the same.
    {
      const double n_theta = g(rng), n_y = g(rng), n_x = g(rng);
      s.sensor.value = SE2(metric.x / scale + o.sensor_sigma_t * n_x, metric.y / scale + o.sensor_sigma_t * n_y,
                           wrap_angle(metric.theta + o.sensor_sigma_theta * n_theta));
    }
    // Isotropic in translation: the same as a covariance of the right perturbation.
    if (o.sensor_sigma_t > 0.0 && o.sensor_sigma_theta > 0.0)
      s.sensor.covariance = Eigen::Vector3d(o.sensor_sigma_t * o.sensor_sigma_t,
                                            o.sensor_sigma_t * o.sensor_sigma_t,
                                            o.sensor_sigma_theta * o.sensor_sigma_theta)
                                .asDiagonal();
    if (o.odometry) {
      const double n_theta = g(rng), n_y = g(rng), n_x = g(rng);  // as above
      s.odometry = Motion{SE2(robot.x + o.odometry_sigma_t * n_x, robot.y + o.odometry_sigma_t * n_y,
                              wrap_angle(robot.theta + o.odometry_sigma_theta * n_theta))};
      if (o.odometry_sigma_t > 0.0 && o.odometry_sigma_theta > 0.0)
        s.odometry->covariance = Eigen::Vector3d(o.odometry_sigma_t * o.odometry_sigma_t,
                                                o.odometry_sigma_t * o.odometry_sigma_t,
                                                o.odometry_sigma_theta * o.odometry_sigma_theta)
                                    .asDiagonal();
    }
    if (o.labels) s.direction = std::abs(v) <= o.in_place_speed ? 0 : (v > 0.0 ? 1 : -1);
    out.samples.push_back(s);
    out.robot.push_back(robot);
  }
  // Gross errors: a translation of 0.5–1 × outlier_size in a random direction.
  const int n_out = static_cast<int>(std::lround(o.outlier_fraction * o.intervals));
  std::vector<int> order(static_cast<size_t>(o.intervals));
  for (int i = 0; i < o.intervals; ++i) order[static_cast<size_t>(i)] = i;
  std::shuffle(order.begin(), order.end(), rng);
  for (int j = 0; j < n_out; ++j) {
    const int i = order[static_cast<size_t>(j)];
    const double a = 2.0 * M_PI * u(rng), m = o.outlier_size * (0.5 + 0.5 * u(rng)) / scale;
    out.samples[static_cast<size_t>(i)].sensor.value.x += m * std::cos(a);
    out.samples[static_cast<size_t>(i)].sensor.value.y += m * std::sin(a);
    out.outliers.push_back(i);
  }
  std::sort(out.outliers.begin(), out.outliers.end());
  return out;
}

}  // namespace planarvo::test
