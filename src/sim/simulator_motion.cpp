// The simulator's motion: smooth piecewise (v, omega) profiles of a differential drive within
// speed and acceleration limits, exact arc integration, wheel odometry with zero-mean errors.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "core/error.h"
#include "sim/simulator.h"

namespace planarvo::sim {

namespace {

constexpr double kDeg = M_PI / 180.0;

// A level of (v, omega) held for `hold` seconds; between consecutive levels the profile blends
// with a half cosine, whose peak slope is (pi/2) * change / duration.
struct Level {
  double v = 0.0, w = 0.0, hold = 0.0;
};

class Profile {
 public:
  Profile(double accel, double angular_accel) : accel_(accel), angular_accel_(angular_accel) {}

  void add(double v, double w, double hold) {
    if (!levels_.empty()) {
      const Level& prev = levels_.back();
      // Shortest blend that keeps both accelerations within their limits.
      double tau = 0.15;
      if (accel_ > 0) tau = std::max(tau, 0.5 * M_PI * std::abs(v - prev.v) / accel_);
      if (angular_accel_ > 0) tau = std::max(tau, 0.5 * M_PI * std::abs(w - prev.w) / angular_accel_);
      blend_.push_back(tau);
    }
    start_.push_back(end_ + (blend_.empty() ? 0.0 : blend_.back()));
    levels_.push_back({v, w, hold});
    end_ = start_.back() + hold;
  }
  double end() const { return end_; }

  // (v, omega) at time t (t >= 0).
  Eigen::Vector2d at(double t) const {
    // The last level whose hold starts at or before t.
    const size_t i = static_cast<size_t>(
        std::upper_bound(start_.begin(), start_.end(), t) - start_.begin() - 1);
    const Level& a = levels_[i];
    const double hold_end = start_[i] + a.hold;
    if (t <= hold_end || i + 1 >= levels_.size()) return {a.v, a.w};
    const Level& b = levels_[i + 1];
    const double s = (t - hold_end) / blend_[i];
    const double f = 0.5 * (1.0 - std::cos(M_PI * std::min(1.0, s)));
    return {a.v + f * (b.v - a.v), a.w + f * (b.w - a.w)};
  }

 private:
  double accel_, angular_accel_;
  std::vector<Level> levels_;
  std::vector<double> start_;  // start of each level's hold
  std::vector<double> blend_;  // blend duration after level i
  double end_ = 0.0;
};

// Each kind's segments, until the profile reaches `duration`.
  // Each segment's random parts are drawn into named values, the duration first, then the turn
  // rate, then the speed: C++ leaves the order of a call's arguments unspecified, and these were
  // once drawn inside p.add(v, w, seconds)'s arguments, so that clang (left to right) made
  // another drive for a seed than GCC (right to left). GCC's order is kept: every drive measured
  // on the simulator stays the same.
void add_mixed(Profile& p, double duration, double vm, double wm, Random& rng) {
  // One cycle takes 7 to 9.5 s at the default limits, so a 10 s sequence has every
  // manoeuvre: driving forwards, arcs turning both ways, stops, turning in place both
  // ways, reversing.
  while (p.end() < duration) {
    const int turn = rng.sign(), spin = rng.sign();
    p.add(0.0, 0.0, rng.uniform(0.2, 0.35));  // stop
    {
      const double s = rng.uniform(0.4, 0.7), w = rng.uniform(-0.05, 0.05) * wm, v = rng.uniform(0.6, 1.0) * vm;
      p.add(v, w, s);
    }
    {
      const double s = rng.uniform(0.4, 0.7), w = turn * rng.uniform(0.4, 0.8) * wm, v = rng.uniform(0.35, 0.6) * vm;
      p.add(v, w, s);
    }
    p.add(0.0, 0.0, rng.uniform(0.1, 0.2));  // stop
    {
      const double s = rng.uniform(0.3, 0.5), w = spin * rng.uniform(0.6, 1.0) * wm;  // in place
      p.add(0.0, w, s);
    }
    {
      const double s = rng.uniform(0.3, 0.5), w = -spin * rng.uniform(0.6, 1.0) * wm;
      p.add(0.0, w, s);
    }
    {
      const double s = rng.uniform(0.5, 0.8), w = -turn * rng.uniform(0.1, 0.5) * wm, v = -rng.uniform(0.35, 0.6) * vm;
      p.add(v, w, s);
    }
    {
      const double s = rng.uniform(0.4, 0.7), w = -turn * rng.uniform(0.4, 0.8) * wm, v = rng.uniform(0.35, 0.6) * vm;
      p.add(v, w, s);
    }
  }
}

void add_straight(Profile& p, double duration, double vm, Random& rng) {
  while (p.end() < duration) {
    p.add(0.0, 0.0, rng.uniform(0.2, 0.4));
    {
      const double s = rng.uniform(0.8, 1.5), v = rng.uniform(0.5, 1.0) * vm;
      p.add(v, 0.0, s);
    }
    p.add(0.0, 0.0, rng.uniform(0.2, 0.4));
    {
      const double s = rng.uniform(0.8, 1.5), v = -rng.uniform(0.5, 1.0) * vm;
      p.add(v, 0.0, s);
    }
  }
}

void add_circle(Profile& p, double vm, double wm, Random& rng) {
  // v and omega blend together, so the curvature is the same from the first interval on.
  const double radius = rng.uniform(0.3, 1.0);
  double v = rng.uniform(0.4, 0.7) * vm;
  if (v / radius > 0.9 * wm) v = 0.9 * wm * radius;
  p.add(0.0, 0.0, 0.2);
  p.add(v, rng.sign() * v / radius, std::numeric_limits<double>::infinity());
}

void add_spin(Profile& p, double duration, double wm, Random& rng) {
  while (p.end() < duration) {
    const int sign = rng.sign();
    p.add(0.0, 0.0, rng.uniform(0.2, 0.4));
    {
      const double s = rng.uniform(0.8, 1.5), w = sign * rng.uniform(0.5, 1.0) * wm;
      p.add(0.0, w, s);
    }
    p.add(0.0, 0.0, rng.uniform(0.2, 0.4));
    {
      const double s = rng.uniform(0.8, 1.5), w = -sign * rng.uniform(0.5, 1.0) * wm;
      p.add(0.0, w, s);
    }
  }
}

void add_car(Profile& p, const Options& o, double duration, double vm, double wm, Random& rng) {
  // Curvature k with |k| <= 1/R; omega = k v, so blends between two levels of the same
  // direction (v and omega blend alike) and through a stop keep |omega| <= |v| / R.
  const double kmax = o.min_turn_radius > 0 ? 1.0 / o.min_turn_radius : HUGE_VAL;
  auto turn = [&](double v, double k) { return std::clamp(k * v, -wm, wm); };
  auto curvature = [&](double share) {
    const double k = share * kmax;
    return std::isfinite(k) ? k : share * 4.0;  // no radius given: up to 4 rad per metre
  };
  // v is drawn before its segment (a statement of its own); then the duration, then the turn.
  const auto add_turning = [&](double v, double share_min, double share_max, double side, double s_min,
                               double s_max) {
    const double s = rng.uniform(s_min, s_max), share = side * rng.uniform(share_min, share_max);
    p.add(v, turn(v, curvature(share)), s);
  };
  while (p.end() < duration) {
    const int side = rng.sign();
    p.add(0.0, 0.0, rng.uniform(0.3, 0.6));  // stop
    double v = rng.uniform(0.6, 1.0) * vm;
    add_turning(v, -0.1, 0.1, 1.0, 1.0, 2.0);  // straight on
    v = rng.uniform(0.4, 0.8) * vm;
    add_turning(v, 0.6, 1.0, side, 1.0, 2.0);  // a bend
    v = rng.uniform(0.6, 1.0) * vm;
    add_turning(v, 0.3, 1.0, -side, 0.8, 1.5);
    p.add(0.0, 0.0, rng.uniform(0.3, 0.6));  // stop
    v = -rng.uniform(0.1, 0.25) * vm;     // reverse
    add_turning(v, 0.5, 1.0, side, 1.0, 2.0);
  }
}

Profile make_profile(const Options& o, double duration, Random& rng) {
  Profile p(o.max_acceleration, o.max_angular_acceleration);
  const double vm = o.max_speed, wm = o.max_turn_rate;
  switch (o.motion) {
    case MotionProfile::Mixed: add_mixed(p, duration, vm, wm, rng); break;
    case MotionProfile::Straight: add_straight(p, duration, vm, rng); break;
    case MotionProfile::Circle: add_circle(p, vm, wm, rng); break;
    case MotionProfile::Spin: add_spin(p, duration, wm, rng); break;
    case MotionProfile::Car: add_car(p, o, duration, vm, wm, rng); break;
  }
  return p;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw_invalid_argument("simulator options: " + what);
}

}  // namespace

const char* motion_profile_name(MotionProfile p) {
  switch (p) {
    case MotionProfile::Mixed: return "mixed";
    case MotionProfile::Straight: return "straight";
    case MotionProfile::Circle: return "circle";
    case MotionProfile::Spin: return "spin";
    case MotionProfile::Car: return "car";
  }
  return "?";
}

Extrinsics default_extrinsics() { return paper_configuration(1); }

Extrinsics paper_configuration(int k) {
  switch (k) {
    case 1: return Extrinsics{0.2441, -0.0185, 0.1787, 12.4 * kDeg, 17.6 * kDeg, -9.2 * kDeg};
    case 2: return Extrinsics{0.1917, -0.1078, 0.2164, 29.8 * kDeg, -4.6 * kDeg, 75.8 * kDeg};
    case 3: return Extrinsics{0.2226, 0.0806, 0.1469, -26.6 * kDeg, 4.7 * kDeg, -18.6 * kDeg};
    default: throw_invalid_argument("the paper's camera configurations are 1, 2 and 3, not " + std::to_string(k));
  }
}

CameraModel default_camera(int width, int height, double fov_deg) {
  CameraModel c;
  c.width = width;
  c.height = height;
  c.k1 = -0.12;
  c.k2 = 0.03;
  // Half the image width sees half the field of view, through the distortion.
  const double xd = c.distort(Eigen::Vector2d(std::tan(0.5 * fov_deg * kDeg), 0.0)).x();
  c.fx = c.fy = 0.5 * width / xd;
  c.cx = 0.5 * (width - 1) + 0.004 * width;
  c.cy = 0.5 * (height - 1) - 0.003 * height;
  return c;
}

double Random::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * M_PI * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * M_PI * u2);
}

uint64_t derive_seed(uint64_t seed, uint64_t stream) {
  uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

void validate(const Options& o) {
  o.camera.validate("simulator camera");
  require(std::isfinite(o.texel_size) && o.texel_size > 0, "texel_size must be positive");
  require(std::isfinite(o.extrinsics.z) && o.extrinsics.z > 0,
          "the camera height extrinsics.z must be positive");
  for (double a : {o.extrinsics.x, o.extrinsics.y, o.extrinsics.roll, o.extrinsics.pitch,
                   o.extrinsics.yaw})
    require(std::isfinite(a), "extrinsics contain NaN or inf");
  if (!o.accept_unusual_extrinsics) check_plausible_extrinsics(o.extrinsics, "simulator options: the extrinsics");
  require(std::isfinite(o.fps) && o.fps > 0, "fps must be positive");
  require(std::isfinite(o.seconds) && std::llround(o.seconds * o.fps) >= 2,
          "seconds * fps must give at least 2 frames");
  require(o.seconds * o.fps <= 1e7, "the sequence is too long");
  require(std::isfinite(o.max_speed) && o.max_speed >= 0, "max_speed must be >= 0");
  require(std::isfinite(o.max_turn_rate) && o.max_turn_rate >= 0, "max_turn_rate must be >= 0");
  require(std::isfinite(o.max_acceleration) && o.max_acceleration > 0,
          "max_acceleration must be positive");
  require(std::isfinite(o.max_angular_acceleration) && o.max_angular_acceleration > 0,
          "max_angular_acceleration must be positive");
  require(std::isfinite(o.min_turn_radius) && o.min_turn_radius >= 0, "min_turn_radius must be >= 0");
  require(std::isfinite(o.pixel_noise) && o.pixel_noise >= 0, "pixel_noise must be >= 0");
  require(std::isfinite(o.gain_variation) && o.gain_variation >= 0 && o.gain_variation < 0.5,
          "gain_variation must be in [0, 0.5)");
  require(std::isfinite(o.odometry_noise) && o.odometry_noise >= 0, "odometry_noise must be >= 0");
  require(std::isfinite(o.odometry_noise_floor) && o.odometry_noise_floor >= 0,
          "odometry_noise_floor must be >= 0");
  require(std::isfinite(o.wheel_base) && o.wheel_base > 0, "wheel_base must be positive");
  require(o.supersampling >= 1 && o.supersampling <= 16, "supersampling must be 1 to 16");
  require(std::isfinite(o.readout_time) && o.readout_time >= 0,
          "readout_time must be a finite number of seconds >= 0");
  require(o.readout_time <= 1.0 / o.fps,
          "readout_time (" + std::to_string(o.readout_time) + " s) must not exceed the frame period 1 / fps (" +
              std::to_string(1.0 / o.fps) + " s): a rolling shutter reads every row of a frame before the next");
  require(std::isfinite(o.exposure_time) && o.exposure_time >= 0,
          "exposure_time must be a finite number of seconds >= 0");
  require(o.exposure_time <= 1.0 / o.fps,
          "exposure_time (" + std::to_string(o.exposure_time) + " s) must not exceed the frame period 1 / fps (" +
              std::to_string(1.0 / o.fps) + " s)");
  require(std::isfinite(o.lamp_falloff) && o.lamp_falloff >= 0 && o.lamp_falloff <= 0.95,
          "lamp_falloff must be in [0, 0.95]");
  require(std::isfinite(o.reflection) && o.reflection >= 0 && o.reflection <= 1000,
          "reflection must be in [0, 1000] grey levels");
  require(std::isfinite(o.shadow) && o.shadow >= 0 && o.shadow <= 0.95, "shadow must be in [0, 0.95]");
  require(std::isfinite(o.lean) && std::abs(o.lean) <= 1.0,
          "lean must be within +-1 s (degrees of body roll per degree/s of yaw rate)");
  require(std::isfinite(o.bumps) && std::abs(o.bumps) <= 20.0 * kDeg, "bumps must be within +-20 degrees");
  require(std::isfinite(o.bump_spacing) && o.bump_spacing > 0 && std::isfinite(o.bump_length) &&
              o.bump_length > 0 && o.bump_length <= o.bump_spacing,
          "bump_spacing and bump_length must be positive, the length at most the spacing");
  require(!std::isnan(o.knock_time) && o.knock_time >= 0, "knock_time must be a time >= 0 (inf: no knock)");
  require(std::isfinite(o.knock_roll) && std::isfinite(o.knock_pitch) && std::isfinite(o.knock_z) &&
              std::abs(o.knock_roll) <= 30.0 * kDeg && std::abs(o.knock_pitch) <= 30.0 * kDeg,
          "the knock's roll and pitch must be finite and within +-30 degrees");
  require(o.extrinsics.z + o.knock_z > 0.2 * o.extrinsics.z,
          "the knock's height change leaves the camera too close to the ground");
  Eigen::Vector2d px;
  const double reach = farthest_ground_view(o.camera, o.extrinsics, &px);
  const std::string at = "pixel (" + std::to_string(static_cast<int>(px.x())) + ", " +
                         std::to_string(static_cast<int>(px.y())) + ")";
  require(std::isfinite(reach), "the camera sees the horizon (the ray of " + at +
                                    " does not meet the ground): tilt it down, narrow its field of view or give a region of "
                                    "interest that leaves the horizon out");
  char far[160];
  std::snprintf(far, sizeof far, "the camera sees ground %.0f camera heights away (%s), more than %.0f", reach,
                at.c_str(), kMaxGroundView);
  require(reach <= kMaxGroundView,
          std::string(far) + ": tilt it down, narrow its field of view or give a region of interest that leaves "
                             "the far ground out");
  require(std::isfinite(o.start_pose.x) && std::isfinite(o.start_pose.y) &&
              std::isfinite(o.start_pose.theta),
          "start_pose contains NaN or inf");
}

Trajectory generate_trajectory(const Options& o) {
  validate(o);
  const size_t n = static_cast<size_t>(std::llround(o.seconds * o.fps));
  const double dt = 1.0 / o.fps;
  Random motion_rng(derive_seed(o.seed, 1));
  Random odo_rng(derive_seed(o.seed, 2));
  const Profile profile = make_profile(o, static_cast<double>(n) * dt, motion_rng);

  Trajectory tr;
  tr.t.resize(n);
  tr.pose.resize(n);
  tr.odometry.resize(n);
  tr.velocity.resize(n - 1);
  tr.direction.resize(n - 1);
  tr.distance.assign(n, 0.0);
  for (size_t k = 0; k < n; ++k) tr.t[k] = static_cast<double>(k) * dt;
  tr.pose[0] = tr.odometry[0] = o.start_pose;
  const double half_base = 0.5 * o.wheel_base;
  for (size_t k = 0; k + 1 < n; ++k) {
    // Constant over the interval: the profile at its middle.
    const Eigen::Vector2d vw = profile.at((static_cast<double>(k) + 0.5) * dt);
    const double v = vw.x(), w = vw.y();
    tr.velocity[k] = vw;
    tr.direction[k] = std::abs(v) < 1e-9 ? 0 : (v > 0 ? 1 : -1);
    tr.pose[k + 1] = tr.pose[k] * SE2::exp(Eigen::Vector3d(v * dt, 0.0, w * dt));
    tr.distance[k + 1] = tr.distance[k] + std::abs(v) * dt;

    // Wheel odometry: each wheel's travel with an unbiased relative error.
    const double left = (v - w * half_base) * dt, right = (v + w * half_base) * dt;
    const double left_m =
        left + (o.odometry_noise * std::abs(left) + o.odometry_noise_floor) * odo_rng.normal();
    const double right_m =
        right + (o.odometry_noise * std::abs(right) + o.odometry_noise_floor) * odo_rng.normal();
    const double ds = 0.5 * (left_m + right_m), dth = (right_m - left_m) / o.wheel_base;
    tr.odometry[k + 1] = tr.odometry[k] * SE2::exp(Eigen::Vector3d(ds, 0.0, dth));
  }
  return tr;
}

}  // namespace planarvo::sim
