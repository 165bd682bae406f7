// The mounting watch (track/mounting_watch.h) on the simulator's body: the true attitude of a car
// leaning in turns and pitching over bumps (sim::body_attitude), with the true motions, plus the
// local plane's measurement error (white noise and a slow wander), is never a change over 20
// drives; a knock added to it is found within the window and measured. And the geometry of a turned
// mounting (core/body_attitude.h) against rotation matrices and plane normals written out here.
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "core/body_attitude.h"
#include "sim/simulator.h"
#include "track/mounting_watch.h"

namespace planarvo::track {
namespace {

constexpr double kDeg = M_PI / 180.0;

sim::Options drive(int seed, double bumps_deg, double max_speed) {
  sim::Options o;
  o.camera = sim::default_camera(160, 120, 60.0);
  o.extrinsics = Extrinsics{-1.0, 0.0, 0.9, 0.0, 40.0 * kDeg, M_PI};
  o.seconds = 20.0;
  o.motion = sim::MotionProfile::Car;
  o.max_speed = max_speed;
  o.min_turn_radius = 6.0;
  o.seed = seed;
  o.lean = -0.07;
  o.bumps = bumps_deg * kDeg;
  return o;
}

struct Outcome {
  std::vector<MountingChange> changes;
};

// Feeds one drive's frames to a watch with the simulator's wheel odometry (1 % noise per wheel and
// frame); the attitude is stepped by `knock` and the camera's height by knock_dz from knock_time on.
// The distances tracked are the true ones times the height the watch has over the true height.
Outcome watch_drive(const sim::Options& o, const BodyAttitude& knock, double knock_time, unsigned noise_seed,
                    double knock_dz = 0.0) {
  const sim::Trajectory tr = sim::generate_trajectory(o);
  std::mt19937 rng(noise_seed);
  std::normal_distribution<double> white(0.0, 0.03 * kDeg);
  MountingWatchOptions wo;
  wo.height = o.extrinsics.z;
  MountingWatch watch(wo);
  Outcome out;
  BodyAttitude absorbed;
  double absorbed_dz = 0.0;
  const Eigen::Matrix2d cov = std::pow(0.03 * kDeg, 2) * Eigen::Matrix2d::Identity();
  for (size_t k = 1; k < tr.t.size(); ++k) {
    const double t = tr.t[k];
    BodyAttitude a = sim::body_attitude(o, tr, t);
    // The local plane's error: white, and a wander of 0.1 degrees over seconds.
    a.roll += white(rng) + 0.1 * kDeg * std::sin(0.9 * t + noise_seed);
    a.pitch += white(rng) + 0.1 * kDeg * std::cos(0.7 * t + noise_seed);
    const double dz = t >= knock_time ? knock_dz : 0.0;
    if (t >= knock_time) {
      a.roll += knock.roll;
      a.pitch += knock.pitch;
    }
    a.roll -= absorbed.roll;  // measured against the mounting recalibrated so far
    a.pitch -= absorbed.pitch;
    SE2 motion = tr.pose[k - 1].inverse() * tr.pose[k];
    const double scale = (o.extrinsics.z + absorbed_dz) / (o.extrinsics.z + dz);
    // The tracker's error (0.03 mm a frame, which standing still makes a distance of its own).
    motion.x = motion.x * scale + 3e-5 * white(rng) / (0.03 * kDeg);
    motion.y = motion.y * scale + 3e-5 * white(rng) / (0.03 * kDeg);
    const SE2 wheels = tr.odometry[k - 1].inverse() * tr.odometry[k];
    if (std::optional<MountingChange> c =
            watch.add(t, tr.t[k] - tr.t[k - 1], motion, a, cov, std::hypot(wheels.x, wheels.y))) {
      out.changes.push_back(*c);
      watch.mounting_changed(*c);  // recalibrated: what follows is against the new mounting
      absorbed.roll += c->step.roll;
      absorbed.pitch += c->step.pitch;
      absorbed_dz += c->dz;
    }
  }
  return out;
}

TEST(MountingWatch, ALeaningBodyIsNeverAKnock) {
  // Twenty 20-s drives: bumps of 3 and 10 degrees, a car at up to 3 m/s and a slow one at up to
  // 1 m/s (its bumps last 2.5 s), turns down to a 6 m radius with the paper's lean.
  int drives = 0;
  double largest_pitch = 0.0, largest_roll = 0.0;
  for (int seed = 1; seed <= 5; ++seed)
    for (double bumps : {3.0, 10.0})
      for (double speed : {1.0, 3.0}) {
        const sim::Options o = drive(seed, bumps, speed);
        const Outcome out = watch_drive(o, BodyAttitude(), HUGE_VAL, static_cast<unsigned>(seed));
        EXPECT_TRUE(out.changes.empty()) << "seed " << seed << " bumps " << bumps << " speed " << speed << ": a change at "
                                         << out.changes.front().detected_time << " s, roll "
                                         << out.changes.front().step.roll / kDeg << " pitch "
                                         << out.changes.front().step.pitch / kDeg << " deg";
        const sim::Trajectory tr = sim::generate_trajectory(o);
        for (double t = 0.0; t < tr.t.back(); t += 0.01) {
          largest_pitch = std::max(largest_pitch, std::abs(sim::body_attitude(o, tr, t).pitch));
          largest_roll = std::max(largest_roll, std::abs(sim::body_attitude(o, tr, t).roll));
        }
        ++drives;
      }
  EXPECT_EQ(drives, 20);
  // Not vacuous: the bodies leant by more than a knock.
  EXPECT_GT(largest_pitch, 9.0 * kDeg);
  EXPECT_GT(largest_roll, 1.0 * kDeg);
}

// The first time after t0 at which the car has driven window_metres (and window_seconds) with its
// acceleration steady and its body's pitch level (no bump): the earliest a window of the new pitch
// can be judged (mounting_watch.h). From the trajectory's velocities and the body's true pitch.
double judgeable_after(const sim::Options& o, const sim::Trajectory& tr, double t0) {
  const MountingWatchOptions w;
  size_t k0 = 1;
  while (k0 < tr.t.size() && tr.t[k0] < t0) ++k0;
  size_t start = k0;
  for (size_t k = k0 + 1; k < tr.t.size(); ++k) {
    const double a = (tr.velocity[k - 1].x() - tr.velocity[k - 2].x()) * 30.0;
    // Not steady: the window restarts.
    if (std::abs(a) > 0.5 * w.min_acceleration_spread || std::abs(sim::body_attitude(o, tr, tr.t[k]).pitch) > 0.2 * kDeg)
      start = k;
    if (tr.distance[k] - tr.distance[start] >= w.window_metres && tr.t[k] - tr.t[start] >= w.window_seconds)
      return tr.t[k];
  }
  return HUGE_VAL;
}

TEST(MountingWatch, AKnockIsFoundOnceAWindowHoldsItAndMeasured) {
  const BodyAttitude knocks[] = {{2.0 * kDeg, 0.0}, {0.0, -2.0 * kDeg}, {-1.5 * kDeg, 1.5 * kDeg}};
  int found = 0, within_a_second = 0;
  for (int seed = 1; seed <= 4; ++seed)
    for (const BodyAttitude& knock : knocks) {
      const sim::Options o = drive(seed, 10.0, 3.0);
      const double knock_time = 7.0 + 0.37 * seed;
      const Outcome out = watch_drive(o, knock, knock_time, static_cast<unsigned>(100 + seed));
      // Each angle found once at most (an angle the first window could not judge comes in a second
      // change), and each change taken into use measured once more (a refinement) at most.
      int changes = 0, refinements = 0;
      double last = 0.0;
      BodyAttitude total;
      for (const MountingChange& c : out.changes) {
        EXPECT_NEAR(c.time, knock_time, 1.01 / o.fps) << "seed " << seed;
        EXPECT_TRUE(c.step.roll == 0.0 || c.sigma(0) > 0.0);
        EXPECT_TRUE(c.step.pitch == 0.0 || c.sigma(1) > 0.0);
        total.roll += c.step.roll;
        total.pitch += c.step.pitch;
        (c.refinement ? refinements : changes) += 1;
        if (!c.refinement) last = c.detected_time;
      }
      ASSERT_GE(changes, 1) << "seed " << seed;
      EXPECT_LE(changes, 2) << "seed " << seed;
      EXPECT_LE(refinements, changes) << "seed " << seed;
      EXPECT_NEAR(total.roll, knock.roll, 0.2 * kDeg) << "seed " << seed;
      EXPECT_NEAR(total.pitch, knock.pitch, 0.2 * kDeg) << "seed " << seed;
      // Found by the frame after the first window that can judge it: a metre driven, and for the
      // pitch at a steady speed off the bumps.
      const sim::Trajectory tr = sim::generate_trajectory(o);
      const double bound = knock.pitch != 0.0 ? judgeable_after(o, tr, knock_time) : [&] {
        size_t k = 0;
        while (tr.t[k] < knock_time) ++k;
        const double s0 = tr.distance[k];
        while (k + 1 < tr.t.size() && tr.distance[k] - s0 < 1.0) ++k;
        return tr.t[k];
      }();
      EXPECT_LE(last, bound + 2.0 / o.fps) << "seed " << seed;
      within_a_second += last - knock_time <= 1.0;
      ++found;
    }
  EXPECT_EQ(found, 12);
  std::printf("knocks found within 1 s: %d of 12\n", within_a_second);
}

TEST(MountingWatch, AHeightChangeIsFoundAgainstTheWheelsAndMeasured) {
  int within_a_second = 0;
  for (int seed = 1; seed <= 4; ++seed)
    for (double dz : {0.01, -0.01}) {
      const sim::Options o = drive(seed, 10.0, 3.0);
      const double knock_time = 7.0 + 0.37 * seed;
      const Outcome out = watch_drive(o, BodyAttitude(), knock_time, static_cast<unsigned>(200 + seed), dz);
      ASSERT_EQ(out.changes.size(), 1u) << "seed " << seed << " dz " << dz;
      EXPECT_FALSE(out.changes[0].refinement);
      const MountingChange& c = out.changes[0];
      EXPECT_NEAR(c.dz, dz, 0.002) << "seed " << seed;
      EXPECT_GT(c.sigma_z, 0.0);
      EXPECT_LT(c.sigma_z, 0.002);
      EXPECT_EQ(c.step.roll, 0.0);
      EXPECT_EQ(c.step.pitch, 0.0);
      EXPECT_NEAR(c.time, knock_time, 0.5) << "seed " << seed;
      // Found once a window of 3 m of wheel travel without a bump (the body's true pitch under
      // 0.3 degrees throughout) lies after it, with half a metre to spare.
      const sim::Trajectory tr = sim::generate_trajectory(o);
      size_t k = 0;
      while (tr.t[k] < knock_time) ++k;
      double s0 = tr.distance[k];
      while (k + 1 < tr.t.size() && tr.distance[k] - s0 < 3.5) {
        if (std::abs(sim::body_attitude(o, tr, tr.t[k]).pitch) > 0.3 * kDeg) s0 = tr.distance[k];
        ++k;
      }
      EXPECT_LE(c.detected_time, tr.t[k]) << "seed " << seed;
      within_a_second += c.detected_time - knock_time <= 1.0;
    }
  std::printf("height changes found within 1 s: %d of 8\n", within_a_second);
}

TEST(BodyAttitude, ATurnedMountingSeesTheGroundAsTheKnockedBodyDid) {
  const Extrinsics mount{-1.0, 0.05, 0.9, 3.0 * kDeg, 40.0 * kDeg, M_PI - 0.1};
  const BodyAttitude step{1.2 * kDeg, -2.5 * kDeg};
  const Extrinsics turned = turned_mounting(mount, step);
  // The camera's centre kept; its orientation R(step) R_vc, written out with angle-axis products.
  EXPECT_NEAR((turned.t_vc() - mount.t_vc()).norm(), 0.0, 1e-12);
  const Eigen::Matrix3d R_step = (Eigen::AngleAxisd(step.roll, Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(step.pitch, Eigen::Vector3d::UnitY()))
                                     .toRotationMatrix();
  EXPECT_LT((turned.R_vc() - R_step * mount.R_vc()).norm(), 1e-12);
  // A body at attitude a on the old mounting, at relative_to_turned(a) on the new one: the same
  // ground normal in the camera (the view of the plane), for attitudes with roll and pitch both.
  for (const BodyAttitude& a : {BodyAttitude{0.0, 0.0}, BodyAttitude{2.0 * kDeg, -1.0 * kDeg}, BodyAttitude{-3.0 * kDeg, 8.0 * kDeg}}) {
    const BodyAttitude b = relative_to_turned(a, step);
    const Eigen::Vector3d n_old = (a.R_plane_body() * mount.R_vc()).transpose() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d n_new = (b.R_plane_body() * turned.R_vc()).transpose() * Eigen::Vector3d::UnitZ();
    EXPECT_LT((n_old - n_new).norm(), 1e-12) << a.roll << " " << a.pitch;
  }
  // attitude_of inverts R_plane_body, and ignores a yaw about the plane's normal.
  const BodyAttitude a{-4.0 * kDeg, 6.5 * kDeg};
  const Eigen::Matrix3d yawed = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix() * a.R_plane_body();
  EXPECT_NEAR(attitude_of(yawed).roll, a.roll, 1e-12);
  EXPECT_NEAR(attitude_of(yawed).pitch, a.pitch, 1e-12);
}

}  // namespace
}  // namespace planarvo::track
