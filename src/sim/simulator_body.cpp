// The body on its suspension: its roll in turns and pitch over bumps relative to the local ground
// plane, and a knock to the camera's mounting (the paper's section 6.4, its Figures 18-19).
// See SIMULATOR.md, "A body that leans".
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "sim/simulator.h"

namespace planarvo::sim {

namespace {

// The yaw rate at time t: linear between the frame intervals' midpoints, held at the ends.
double yaw_rate(const Trajectory& tr, double t) {
  const size_t m = tr.velocity.size();
  if (m == 0 || tr.t.size() != m + 1) return 0.0;
  auto mid = [&](size_t i) { return 0.5 * (tr.t[i] + tr.t[i + 1]); };
  if (!(t > mid(0))) return tr.velocity.front().y();
  if (t >= mid(m - 1)) return tr.velocity.back().y();
  // The interval whose midpoint is the last at or before t.
  const size_t k = std::min(m - 2, static_cast<size_t>(std::upper_bound(tr.t.begin(), tr.t.end(), t) - tr.t.begin()) - 1);
  const size_t i = t >= mid(k) ? k : k - 1;
  const double f = (t - mid(i)) / (mid(i + 1) - mid(i));
  return tr.velocity[i].y() + f * (tr.velocity[i + 1].y() - tr.velocity[i].y());
}

// The distance driven up to time t (frames' distances, the interval's |v| in between).
double distance_at(const Trajectory& tr, double t) {
  if (tr.distance.size() != tr.t.size())
    throw_invalid_argument("body_attitude: the trajectory has no distances (bumps need them)");
  if (tr.t.empty() || !(t > tr.t.front())) return 0.0;
  const size_t k = static_cast<size_t>(std::upper_bound(tr.t.begin(), tr.t.end(), t) - tr.t.begin()) - 1;
  const double v = tr.velocity.empty() ? 0.0 : tr.velocity[std::min(k, tr.velocity.size() - 1)].x();
  return tr.distance[k] + std::abs(v) * (t - tr.t[k]);
}

// One bump's pitch profile over u in [0, 1], peak 1: sin(2 pi u) sin^2(pi u) / (3 sqrt(3) / 8).
// Zero with zero slope at both ends; +1 at u = 1/3, -1 at u = 2/3.
double bump_profile(double u) {
  if (!(u > 0.0 && u < 1.0)) return 0.0;
  const double s = std::sin(M_PI * u);
  return std::sin(2.0 * M_PI * u) * s * s / (3.0 * std::sqrt(3.0) / 8.0);
}

}  // namespace

BodyAttitude body_attitude(const Options& o, const Trajectory& tr, double t) {
  BodyAttitude a;
  if (o.lean != 0.0) a.roll = o.lean * yaw_rate(tr, t);
  if (o.bumps != 0.0) {
    const double s = distance_at(tr, t) - 0.5 * o.bump_spacing;  // the first bump at half a spacing
    if (s > 0.0) {
      const double into = s - o.bump_spacing * std::floor(s / o.bump_spacing);
      a.pitch = o.bumps * bump_profile(into / o.bump_length);
    }
  }
  return a;
}

Extrinsics knocked_extrinsics(const Options& o) {
  Extrinsics e = o.extrinsics;
  if (std::isfinite(o.knock_time)) {
    e.roll += o.knock_roll;
    e.pitch += o.knock_pitch;
    e.z += o.knock_z;
  }
  return e;
}

Extrinsics camera_extrinsics_at(const Options& o, const Trajectory& tr, double t) {
  const Extrinsics mount = t >= o.knock_time ? knocked_extrinsics(o) : o.extrinsics;
  return on_plane(mount, body_attitude(o, tr, t));
}

}  // namespace planarvo::sim
