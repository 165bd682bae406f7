#include "track/body_lean.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace planarvo::track {

BodyLean fit_body_lean(const std::vector<double>& t, const std::vector<SE2>& motion, const std::vector<double>& roll,
                       const std::vector<double>& pitch, const std::vector<bool>& use) {
  const size_t n = t.size();
  if (motion.size() != n || roll.size() != n || pitch.size() != n || use.size() != n)
    throw_invalid_argument("fit_body_lean: times, motions, attitudes and flags must be as many");
  // Per interval k (ending at frame k): forward speed and yaw rate.
  std::vector<double> v(n, 0.0), w(n, 0.0);
  std::vector<bool> ok(n, false);
  for (size_t k = 1; k < n; ++k) {
    const double dt = t[k] - t[k - 1];
    if (!(dt > 0) || !std::isfinite(dt)) continue;
    const Eigen::Vector3d xi = motion[k].log();
    v[k] = xi.x() / dt;
    w[k] = xi.z() / dt;
    ok[k] = use[k] && std::isfinite(v[k] + w[k] + roll[k] + pitch[k]);
  }
  BodyLean out;
  std::vector<double> xr, yr, xp, yp;
  for (size_t k = 1; k < n; ++k) {
    if (!ok[k]) continue;
    // The frame's yaw rate: the mean of its two intervals' when the next one is known too.
    const bool next = k + 1 < n && ok[k + 1];
    xr.push_back(next ? 0.5 * (w[k] + w[k + 1]) : w[k]);
    yr.push_back(roll[k]);
    if (next) {
      const double dt = 0.5 * (t[k + 1] - t[k - 1]);
      xp.push_back((v[k + 1] - v[k]) / dt);
      yp.push_back(pitch[k]);
    }
  }
  out.roll_per_yaw_rate = fit_line(xr, yr);
  out.pitch_per_acceleration = fit_line(xp, yp);
  return out;
}

}  // namespace planarvo::track
