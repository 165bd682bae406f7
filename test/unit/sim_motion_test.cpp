// The simulator's motion: nonholonomic arcs, limits, the manoeuvres each profile promises,
// unbiased wheel odometry of the requested size, determinism; and its random numbers.
#include <algorithm>
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "core/error.h"
#include "sim/simulator.h"

namespace planarvo::sim {
namespace {

Options motion_options(MotionProfile profile, uint64_t seed, double seconds = 10.0) {
  Options o;
  o.motion = profile;
  o.seed = seed;
  o.seconds = seconds;
  return o;
}

const MotionProfile kProfiles[] = {MotionProfile::Mixed, MotionProfile::Straight, MotionProfile::Circle,
                                   MotionProfile::Spin, MotionProfile::Car};

TEST(SimMotion, SizesAndTimes) {
  const Trajectory tr = generate_trajectory(motion_options(MotionProfile::Mixed, 1));
  ASSERT_EQ(tr.t.size(), 300u);
  EXPECT_EQ(tr.pose.size(), 300u);
  EXPECT_EQ(tr.odometry.size(), 300u);
  EXPECT_EQ(tr.velocity.size(), 299u);
  EXPECT_EQ(tr.direction.size(), 299u);
  for (size_t k = 0; k < tr.t.size(); ++k) EXPECT_DOUBLE_EQ(tr.t[k], static_cast<double>(k) / 30.0);
  EXPECT_EQ(tr.pose[0].x, 0.0);
  EXPECT_EQ(tr.pose[0].theta, 0.0);
}

// Each interval is the arc of its constant (v, omega): zero lateral velocity in the robot
// frame, checked with the arc-form residual of conventions.md, and the motion is exactly
// exp((v dt, 0, omega dt)).
TEST(SimMotion, IntervalsAreNonholonomicArcs) {
  for (MotionProfile profile : kProfiles)
    for (uint64_t seed : {1u, 2u, 3u}) {
      Options o = motion_options(profile, seed);
      o.start_pose = SE2(12.5, -3.25, 2.0);
      const Trajectory tr = generate_trajectory(o);
      const double dt = 1.0 / o.fps;
      for (size_t k = 0; k + 1 < tr.pose.size(); ++k) {
        const SE2 m = tr.pose[k].inverse() * tr.pose[k + 1];
        const double e = m.y * std::cos(m.theta / 2) - m.x * std::sin(m.theta / 2);
        ASSERT_LT(std::abs(e), 1e-12) << "profile " << static_cast<int>(profile) << " interval " << k;
        const Eigen::Vector3d xi = m.log();
        ASSERT_NEAR(xi.x(), tr.velocity[k].x() * dt, 1e-12);
        ASSERT_NEAR(xi.y(), 0.0, 1e-12);
        ASSERT_NEAR(xi.z(), tr.velocity[k].y() * dt, 1e-12);
      }
    }
}

TEST(SimMotion, LimitsAreRespected) {
  for (MotionProfile profile : kProfiles)
    for (uint64_t seed = 1; seed <= 10; ++seed) {
      Options o = motion_options(profile, seed, 30.0);
      if (seed % 2 == 0) {  // other limits are honoured too
        o.max_speed = 0.3;
        o.max_turn_rate = 0.7;
        o.max_acceleration = 0.5;
        o.max_angular_acceleration = 1.0;
        o.fps = 20;
      }
      const Trajectory tr = generate_trajectory(o);
      const double dt = 1.0 / o.fps;
      Eigen::Vector2d prev(0, 0);  // at rest before the first frame
      for (size_t k = 0; k < tr.velocity.size(); ++k) {
        const Eigen::Vector2d& vw = tr.velocity[k];
        ASSERT_LE(std::abs(vw.x()), o.max_speed * (1 + 1e-12)) << k;
        ASSERT_LE(std::abs(vw.y()), o.max_turn_rate * (1 + 1e-12)) << k;
        ASSERT_LE(std::abs(vw.x() - prev.x()) / dt, o.max_acceleration * (1 + 1e-9)) << k;
        ASSERT_LE(std::abs(vw.y() - prev.y()) / dt, o.max_angular_acceleration * (1 + 1e-9)) << k;
        prev = vw;
      }
    }
}

TEST(SimMotion, DirectionLabelsFollowTheSignOfV) {
  const Trajectory tr = generate_trajectory(motion_options(MotionProfile::Mixed, 5, 20.0));
  for (size_t k = 0; k < tr.velocity.size(); ++k) {
    const double v = tr.velocity[k].x();
    ASSERT_EQ(tr.direction[k], v > 0 ? 1 : (v < 0 ? -1 : 0)) << k;
  }
}

// Everything calibration needs, in every 10 s mixed sequence.
TEST(SimMotion, MixedHasEveryManoeuvreInTenSeconds) {
  for (uint64_t seed = 1; seed <= 30; ++seed) {
    const Trajectory tr = generate_trajectory(motion_options(MotionProfile::Mixed, seed));
    bool forward = false, backward = false, left = false, right = false;
    bool spin_left = false, spin_right = false, stop = false, arc_left = false, arc_right = false;
    for (size_t k = 0; k < tr.velocity.size(); ++k) {
      const double v = tr.velocity[k].x(), w = tr.velocity[k].y();
      forward |= v > 0.2;
      backward |= v < -0.2;
      left |= w > 0.5;
      right |= w < -0.5;
      arc_left |= std::abs(v) > 0.2 && w > 0.3;
      arc_right |= std::abs(v) > 0.2 && w < -0.3;
      spin_left |= tr.direction[k] == 0 && w > 0.5;
      spin_right |= tr.direction[k] == 0 && w < -0.5;
      stop |= v == 0.0 && w == 0.0;
    }
    EXPECT_TRUE(forward && backward) << "seed " << seed;
    EXPECT_TRUE(left && right) << "seed " << seed;
    EXPECT_TRUE(arc_left && arc_right) << "seed " << seed;
    EXPECT_TRUE(spin_left && spin_right) << "seed " << seed;
    EXPECT_TRUE(stop) << "seed " << seed;
  }
}

TEST(SimMotion, StraightStaysOnOneLineBothWays) {
  Options o = motion_options(MotionProfile::Straight, 3);
  o.start_pose = SE2(1.0, 2.0, 0.5);
  const Trajectory tr = generate_trajectory(o);
  bool forward = false, backward = false;
  for (size_t k = 0; k < tr.velocity.size(); ++k) {
    EXPECT_EQ(tr.velocity[k].y(), 0.0);
    forward |= tr.direction[k] > 0;
    backward |= tr.direction[k] < 0;
  }
  EXPECT_TRUE(forward && backward);
  for (const SE2& p : tr.pose) {
    const Eigen::Vector2d local = o.start_pose.inverse() * Eigen::Vector2d(p.x, p.y);
    EXPECT_NEAR(local.y(), 0.0, 1e-12);
    EXPECT_NEAR(wrap_angle(p.theta - 0.5), 0.0, 1e-12);
  }
}

TEST(SimMotion, CircleHasConstantCurvature) {
  for (uint64_t seed : {1u, 2u, 3u, 4u}) {
    const Trajectory tr = generate_trajectory(motion_options(MotionProfile::Circle, seed));
    double kappa = 0.0;
    int moving = 0;
    for (const Eigen::Vector2d& vw : tr.velocity) {
      if (vw.x() == 0.0) {
        EXPECT_EQ(vw.y(), 0.0);
        continue;
      }
      if (moving++ == 0) kappa = vw.y() / vw.x();
      EXPECT_NEAR(vw.y() / vw.x(), kappa, 1e-9 * std::abs(kappa));
    }
    ASSERT_GT(moving, 200);
    // The poses lie on one circle of radius 1/|kappa| around a fixed centre.
    const double r = 1.0 / kappa;
    const Eigen::Vector2d centre(0.0, r);  // left of the start pose for kappa > 0
    for (const SE2& p : tr.pose)
      EXPECT_NEAR((Eigen::Vector2d(p.x, p.y) - centre).norm(), std::abs(r), 1e-9);
  }
}

TEST(SimMotion, SpinTurnsInPlaceBothWays) {
  const Trajectory tr = generate_trajectory(motion_options(MotionProfile::Spin, 7));
  bool left = false, right = false;
  for (size_t k = 0; k < tr.velocity.size(); ++k) {
    EXPECT_EQ(tr.velocity[k].x(), 0.0);
    EXPECT_EQ(tr.direction[k], 0);
    left |= tr.velocity[k].y() > 0.5;
    right |= tr.velocity[k].y() < -0.5;
  }
  EXPECT_TRUE(left && right);
  for (const SE2& p : tr.pose) {
    EXPECT_EQ(p.x, 0.0);
    EXPECT_EQ(p.y, 0.0);
  }
}

// A car at up to 3 m/s with a turning radius of at least 6 m: every interval's arc is no tighter
// (|omega| <= |v| / R, never turning in place), it drives forwards most of the time, turns both
// ways and reverses.
TEST(SimMotion, CarKeepsItsTurningRadius) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    Options o = motion_options(MotionProfile::Car, seed, 20.0);
    o.max_speed = 3.0;
    o.min_turn_radius = 6.0;
    const Trajectory tr = generate_trajectory(o);
    double forward = 0, backward = 0;
    bool left = false, right = false;
    for (size_t k = 0; k < tr.velocity.size(); ++k) {
      const double v = tr.velocity[k].x(), w = tr.velocity[k].y();
      ASSERT_LE(std::abs(w), std::abs(v) / o.min_turn_radius * (1 + 1e-12) + 1e-15) << seed << " " << k;
      forward += v > 0 ? v / o.fps : 0;
      backward += v < 0 ? -v / o.fps : 0;
      left |= w > 0.1 && v > 0;
      right |= w < -0.1 && v > 0;
    }
    EXPECT_GT(forward, 5 * backward) << seed;
    EXPECT_GT(backward, 0.5) << seed;
    EXPECT_TRUE(left && right) << seed;
  }
}

// A camera that sees the horizon, or ground farther than kMaxGroundView heights, is refused
// with the reason; its distance is that of the border pixel, computed here independently for
// a pinhole camera tilted about the robot's y axis (a rear camera looking back).
TEST(SimMotion, RefusesACameraThatSeesTheHorizon) {
  Options o;
  o.camera = default_camera(640, 480, 60.0);
  o.camera.k1 = o.camera.k2 = 0.0;
  o.extrinsics = Extrinsics{-1.0, 0.0, 0.9, 0.0, 40.0 * M_PI / 180.0, M_PI};
  EXPECT_NO_THROW(validate(o));
  // A pinhole camera tilted by phi about its x axis: the ray (a, b, 1) meets the ground at
  // hypot(sin phi + b cos phi, a) / (cos phi - b sin phi) heights; the farthest border pixel is
  // a corner of the far row. Which row is far depends on the direction of the tilt in the
  // image, so both are computed and the function must give one of them.
  const double phi = 40.0 * M_PI / 180.0;
  const double as[2] = {-o.camera.cx / o.camera.fx, (o.camera.width - 1 - o.camera.cx) / o.camera.fx};
  const double bs[2] = {-o.camera.cy / o.camera.fy, (o.camera.height - 1 - o.camera.cy) / o.camera.fy};
  double expected[2] = {0, 0};
  for (int sign = 0; sign < 2; ++sign)
    for (double a : as)
      for (double b0 : bs) {
        const double b = sign ? -b0 : b0;
        expected[sign] = std::max(expected[sign], std::hypot(std::sin(phi) + b * std::cos(phi), a) /
                                                      (std::cos(phi) - b * std::sin(phi)));
      }
  const double reach = farthest_ground_view(o.camera, o.extrinsics);
  EXPECT_TRUE(std::abs(reach - expected[0]) < 1e-9 * reach || std::abs(reach - expected[1]) < 1e-9 * reach)
      << reach << " " << expected[0] << " " << expected[1];
  for (double pitch_deg : {70.0, 95.0}) {
    o.extrinsics.pitch = pitch_deg * M_PI / 180.0;
    try {
      validate(o);
      ADD_FAILURE() << pitch_deg << " degrees from vertical was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
    }
  }
  EXPECT_FALSE(std::isfinite(farthest_ground_view(o.camera, o.extrinsics)));
}

// A region of interest that leaves the horizon out admits a camera that sees it, and how far the
// camera sees is then the farthest ground any pixel of the region sees (every pixel tried, not
// only the border the function walks).
TEST(SimMotion, ARegionOfInterestAdmitsACameraThatSeesTheHorizon) {
  Options o;
  o.camera = default_camera(320, 240, 60.0);
  o.extrinsics = Extrinsics{-1.0, 0.0, 0.9, 0.0, 66.0 * M_PI / 180.0, M_PI};
  EXPECT_THROW(validate(o), Error);
  EXPECT_FALSE(farthest_ground_view(o.camera, o.extrinsics) <= kMaxGroundView);
  int accepted = 0;
  for (const PixelRegion& roi : {PixelRegion{0, 0, 320, 150}, PixelRegion{0, 90, 320, 150}}) {
    o.camera.roi = roi;
    double brute = 0.0;
    const Eigen::Matrix3d R = o.extrinsics.R_vc();
    for (int v = roi.y; v < roi.y + roi.height; ++v)
      for (int u = roi.x; u < roi.x + roi.width; ++u) {
        const Eigen::Vector2d xn = o.camera.unproject(Eigen::Vector2d(u, v));
        const Eigen::Vector3d dir = R * Eigen::Vector3d(xn.x(), xn.y(), 1.0);
        brute = std::max(brute, dir.z() < 0.0 ? std::hypot(dir.x(), dir.y()) / -dir.z() : HUGE_VAL);
      }
    const double reach = farthest_ground_view(o.camera, o.extrinsics);
    if (std::isfinite(brute)) {
      EXPECT_NEAR(reach, brute, 1e-9 * brute);
    } else {
      EXPECT_FALSE(std::isfinite(reach));
    }
    if (reach <= kMaxGroundView) {
      EXPECT_NO_THROW(validate(o));
      ++accepted;
    } else {
      EXPECT_THROW(validate(o), Error);
    }
  }
  EXPECT_EQ(accepted, 1) << "one of the two halves sees the near ground only";
}

// The wheel travel recovered from the odometry poses has an unbiased relative error of the
// requested size, and the odometry itself moves along arcs (it is a differential drive too).
TEST(SimMotion, OdometryErrorIsZeroMeanAndOfTheRequestedSize) {
  for (double sigma : {0.01, 0.05}) {
    Options o = motion_options(MotionProfile::Mixed, 11, 300.0);
    o.odometry_noise = sigma;
    const Trajectory tr = generate_trajectory(o);
    const double dt = 1.0 / o.fps, b = o.wheel_base;
    double sum = 0.0, sum2 = 0.0;
    int count = 0;
    for (size_t k = 0; k + 1 < tr.odometry.size(); ++k) {
      const Eigen::Vector3d xi = (tr.odometry[k].inverse() * tr.odometry[k + 1]).log();
      ASSERT_NEAR(xi.y(), 0.0, 1e-12);
      const double v = tr.velocity[k].x(), w = tr.velocity[k].y();
      const double true_wheel[2] = {(v - w * b / 2) * dt, (v + w * b / 2) * dt};
      const double odo_wheel[2] = {xi.x() - xi.z() * b / 2, xi.x() + xi.z() * b / 2};
      for (int i = 0; i < 2; ++i) {
        if (std::abs(true_wheel[i]) < 5e-3) continue;  // where the absolute floor is negligible
        const double e = (odo_wheel[i] - true_wheel[i]) / std::abs(true_wheel[i]);
        sum += e;
        sum2 += e * e;
        ++count;
      }
    }
    ASSERT_GT(count, 5000);
    const double mean = sum / count, sd = std::sqrt(sum2 / count - mean * mean);
    EXPECT_LT(std::abs(mean), 4.0 * sd / std::sqrt(count)) << "sigma " << sigma;
    EXPECT_NEAR(sd, sigma, 0.05 * sigma) << "sigma " << sigma;
  }
}

TEST(SimMotion, OdometryDriftsFromTheTruth) {
  const Trajectory tr = generate_trajectory(motion_options(MotionProfile::Mixed, 1));
  const SE2 d = tr.pose.back().inverse() * tr.odometry.back();
  EXPECT_GT(std::hypot(d.x, d.y) + std::abs(d.theta), 1e-5);
  EXPECT_LT(std::hypot(d.x, d.y), 0.2);
}

TEST(SimMotion, DeterministicForASeed) {
  for (MotionProfile profile : kProfiles) {
    const Trajectory a = generate_trajectory(motion_options(profile, 42));
    const Trajectory b = generate_trajectory(motion_options(profile, 42));
    const Trajectory c = generate_trajectory(motion_options(profile, 43));
    bool differs = false;
    for (size_t k = 0; k < a.pose.size(); ++k) {
      ASSERT_EQ(a.pose[k].x, b.pose[k].x);
      ASSERT_EQ(a.pose[k].y, b.pose[k].y);
      ASSERT_EQ(a.pose[k].theta, b.pose[k].theta);
      ASSERT_EQ(a.odometry[k].x, b.odometry[k].x);
      ASSERT_EQ(a.odometry[k].theta, b.odometry[k].theta);
      differs |= a.pose[k].x != c.pose[k].x || a.odometry[k].x != c.odometry[k].x;
    }
    EXPECT_TRUE(differs) << "profile " << static_cast<int>(profile);
  }
}

TEST(SimMotion, RejectsBadOptions) {
  Options o;
  o.fps = 0;
  EXPECT_THROW(generate_trajectory(o), Error);
  o = Options();
  o.seconds = 0.01;
  EXPECT_THROW(generate_trajectory(o), Error);
  o = Options();
  o.max_acceleration = 0;
  EXPECT_THROW(generate_trajectory(o), Error);
  o = Options();
  o.odometry_noise = -1;
  EXPECT_THROW(generate_trajectory(o), Error);
}

// The random numbers are pinned: the same on every platform and standard library.
TEST(SimRandom, PinnedSequence) {
  Random r(derive_seed(1, 0));
  const double u = r.uniform();
  const double n1 = r.normal(), n2 = r.normal();
  EXPECT_EQ(derive_seed(1, 0), 0x910a2dec89025cc1ULL);
  // Recompute the pinned values from the documented construction.
  std::mt19937_64 g(derive_seed(1, 0));
  EXPECT_EQ(u, static_cast<double>(g() >> 11) * 0x1.0p-53);
  const double u1 = 1.0 - static_cast<double>(g() >> 11) * 0x1.0p-53;
  const double u2 = static_cast<double>(g() >> 11) * 0x1.0p-53;
  EXPECT_EQ(n1, std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2));
  EXPECT_EQ(n2, std::sqrt(-2.0 * std::log(u1)) * std::sin(2.0 * M_PI * u2));
}

TEST(SimRandom, NormalHasUnitVariance) {
  Random r(7);
  double s = 0, s2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double x = r.normal();
    s += x;
    s2 += x * x;
  }
  EXPECT_NEAR(s / n, 0.0, 0.01);
  EXPECT_NEAR(s2 / n, 1.0, 0.01);
}

}  // namespace
}  // namespace planarvo::sim
