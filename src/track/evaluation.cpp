#include "track/evaluation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace planarvo::track {

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  LineFit f;
  const size_t n = std::min(x.size(), y.size());
  f.samples = static_cast<int>(n);
  f.slope_sigma = HUGE_VAL;
  if (n < 2) return f;
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double sxx = 0, sxy = 0, syy = 0;
  for (size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (!(sxx > 0)) {
    f.offset = my;
    return f;
  }
  f.slope = sxy / sxx;
  f.offset = my - f.slope * mx;
  const double rss = std::max(0.0, syy - f.slope * sxy);
  if (n >= 3) f.slope_sigma = std::sqrt(rss / static_cast<double>(n - 2) / sxx);
  f.r2 = syy > 0 ? 1.0 - rss / syy : 0.0;
  return f;
}

MotionAccuracy evaluate_motions(const std::vector<SE2>& estimated, const std::vector<SE2>& truth,
                                const std::vector<double>& dt, double gross_threshold,
                                const std::vector<bool>& valid) {
  if (estimated.size() != truth.size() || dt.size() != truth.size() ||
      (!valid.empty() && valid.size() != truth.size()))
    throw_invalid_argument("evaluate_motions: " + std::to_string(estimated.size()) + " estimates, " +
                           std::to_string(truth.size()) + " true motions, " + std::to_string(dt.size()) +
                           " durations");
  MotionAccuracy a;
  std::vector<double> v_true, v_est, w_true, w_est;
  double sq_t = 0, sq_r = 0;
  SE2 pose_est, pose_true;
  for (size_t i = 0; i < truth.size(); ++i) {
    const SE2 &e = estimated[i], &g = truth[i];
    pose_est = pose_est * e;
    pose_true = pose_true * g;
    a.distance += std::hypot(g.x, g.y);
    if (!valid.empty() && !valid[i]) continue;
    if (!(dt[i] > 0)) throw_invalid_argument("evaluate_motions: interval durations must be positive");
    const double et = std::hypot(e.x - g.x, e.y - g.y);
    const double er = wrap_angle(e.theta - g.theta);
    sq_t += et * et;
    sq_r += er * er;
    a.max_translation = std::max(a.max_translation, et);
    if (et > gross_threshold) ++a.gross_errors;
    v_true.push_back(g.x / dt[i]);
    v_est.push_back(e.x / dt[i]);
    w_true.push_back(g.theta / dt[i]);
    w_est.push_back(e.theta / dt[i]);
    ++a.intervals;
  }
  if (a.intervals > 0) {
    a.rms_translation = std::sqrt(sq_t / a.intervals);
    a.rms_rotation = std::sqrt(sq_r / a.intervals);
  }
  a.slope_linear = fit_line(v_true, v_est).slope;
  a.slope_angular = fit_line(w_true, w_est).slope;
  a.endpoint_error = std::hypot(pose_est.x - pose_true.x, pose_est.y - pose_true.y);
  a.endpoint_drift = a.distance > 0 ? a.endpoint_error / a.distance : 0;
  a.endpoint_heading = std::abs(wrap_angle(pose_est.theta - pose_true.theta));
  return a;
}

}  // namespace planarvo::track
