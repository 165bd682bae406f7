#include "track/mounting_watch.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

#include "track/evaluation.h"

namespace planarvo::track {

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m), v.end());
  double med = v[m];
  if (v.size() % 2 == 0) med = 0.5 * (med + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m)));
  return med;
}

// The normal-equivalent standard deviation of v about its median (1.4826 MAD).
double robust_scale(const std::vector<double>& v, double med) {
  std::vector<double> d(v.size());
  for (size_t i = 0; i < v.size(); ++i) d[i] = std::abs(v[i] - med);
  return 1.4826 * median(d);
}

double spread(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  double m = 0.0;
  for (double x : v) m += x;
  m /= static_cast<double>(v.size());
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

// y = k x + c by least squares, once more without the points beyond 3 robust sigma of the first
// line (a bump's pitch, a turn's entry while the body still settles).
double robust_slope(const std::vector<double>& x, const std::vector<double>& y, double floor) {
  LineFit f = fit_line(x, y);
  std::vector<double> r(x.size());
  for (size_t i = 0; i < x.size(); ++i) r[i] = y[i] - (f.slope * x[i] + f.offset);
  const double s = std::max(robust_scale(r, median(r)), floor);
  std::vector<double> xi, yi;
  for (size_t i = 0; i < x.size(); ++i)
    if (std::abs(r[i]) <= 3.0 * s) {
      xi.push_back(x[i]);
      yi.push_back(y[i]);
    }
  if (xi.size() >= 10) f = fit_line(xi, yi);
  return std::isfinite(f.slope) ? f.slope : 0.0;
}

}  // namespace

void MountingWatch::reset() {
  samples_.clear();
  level_ = BodyAttitude();
  k_roll_ = 0.0;
  lean_known_ = false;
  since_[0] = since_[1] = since_[2] = since_[3] = -HUGE_VAL;
  refining_[0] = refining_[1] = false;
  distance_ = 0.0;
  has_speed_ = false;
}

void MountingWatch::mounting_changed(const MountingChange& change) {
  // A change the caller took into use is measured once more from frames tracked with it: the
  // frames before it was found were tracked with the camera turned and the body's model not (the
  // local plane turns the body about the ground), which biases their attitude a little.
  if (!change.refinement && (change.step.roll != 0.0 || change.step.pitch != 0.0)) {
    refining_[0] = change.step.roll != 0.0;
    refining_[1] = change.step.pitch != 0.0;
    refine_base_[0] = last_bases_[0];
    refine_base_[1] = last_bases_[1];
    refine_after_ = change.detected_time;
    refine_time_ = change.time;
  }
  level_.roll -= change.step.roll;
  level_.pitch -= change.step.pitch;
  const double scale = opt_.height > 0.0 ? (opt_.height + change.dz) / opt_.height : 1.0;
  for (Sample& s : samples_) {
    if (s.t >= since_[0]) s.roll -= change.step.roll;  // measured with the mounting as it now is
    if (s.t >= since_[1]) s.pitch -= change.step.pitch;
    if (s.t >= since_[2]) s.vis *= scale;
    if (s.t >= since_[3]) s.heading += change.dyaw;
  }
  opt_.height += change.dz;
}

std::optional<MountingChange> MountingWatch::add(double t, double dt, const SE2& motion, const BodyAttitude& attitude,
                                                 const Eigen::Matrix2d& covariance, double odometry_distance) {
  if (!(dt > 0.0) || !std::isfinite(t) || !std::isfinite(attitude.roll + attitude.pitch)) {
    has_speed_ = false;
    return std::nullopt;
  }
  const double v = motion.x / dt;
  Sample s;
  s.t = t;
  s.vis = std::hypot(motion.x, motion.y);
  distance_ += s.vis;
  s.s = distance_;
  s.w = motion.theta / dt;
  s.a = has_speed_ ? (v - last_speed_) / dt : 0.0;
  last_speed_ = v;
  has_speed_ = true;
  s.roll = attitude.roll;
  s.pitch = attitude.pitch;
  s.var_roll = std::isfinite(covariance(0, 0)) ? covariance(0, 0) : 0.0;
  s.var_pitch = std::isfinite(covariance(1, 1)) ? covariance(1, 1) : 0.0;
  // The direction of travel in the robot frame (backwards turned round), less the half of the
  // frame's turn that an arc's chord has: zero for a car (its origin on the rear axle) whatever it
  // turns; NaN when it hardly moves.
  s.heading = std::abs(motion.x) >= opt_.min_heading_speed * dt
                  ? std::atan2(motion.x > 0 ? motion.y : -motion.y, std::abs(motion.x)) - 0.5 * motion.theta *
                                                                                         (motion.x > 0 ? 1.0 : -1.0)
                  : NAN;
  s.odo = std::isfinite(odometry_distance) && odometry_distance >= 0.0 ? odometry_distance : NAN;
  samples_.push_back(s);
  return test();
}

void MountingWatch::fit_lean(size_t end) {
  std::vector<double> w, roll;
  for (size_t i = 0; i < end; ++i) {
    if (samples_[i].t < since_[0]) continue;  // before the roll's last change: another level
    w.push_back(samples_[i].w);
    roll.push_back(samples_[i].roll);
  }
  if (w.size() >= 30 && spread(w) >= opt_.min_yaw_rate_spread) {
    k_roll_ = robust_slope(w, roll, 0.02 * M_PI / 180.0);
    lean_known_ = true;
  }
}

// One angle's judgement over the window against the history before it (test()): the window's
// median level, the step from the history's level, its standard deviation, and whether the window
// was steady and driven comparably enough to judge.
MountingWatch::AngleJudgement MountingWatch::judge_angle(int angle, size_t begin) const {
  const size_t n = samples_.size();
  auto in_history = [&](size_t i) { return i < begin && samples_[i].t >= since_[angle]; };
  AngleJudgement j;
  std::vector<double> win, hist, x_win, x_hist;
  double var_w = 0.0, var_h = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double var = angle == 0 ? samples_[i].var_roll : samples_[i].var_pitch;
    const double x = angle == 0 ? samples_[i].w : samples_[i].a;
    if (i >= begin) {
      x_win.push_back(x);
      win.push_back(residual(samples_[i], angle));
      var_w += var;
    } else if (in_history(i)) {
      x_hist.push_back(x);
      hist.push_back(residual(samples_[i], angle));
      var_h += var;
    }
  }
  const double med = median(win);
  double worst = 0.0;
  for (double r : win) worst = std::max(worst, std::abs(r - med));
  const bool has_history = hist.size() >= 10;
  // A window driven otherwise than the history (a turn after a straight, braking after cruising)
  // may lean by its own drive: no level to compare with, unless the roll's slope is known.
  const double x_spread = angle == 0 ? opt_.min_yaw_rate_spread : opt_.min_acceleration_spread;
  const double x_base = has_history ? median(x_hist) : 0.0;
  const bool comparable = (angle == 0 && lean_known_) || std::abs(median(x_win) - x_base) <= x_spread;
  j.base = has_history ? median(hist) : (angle == 0 ? level_.roll : level_.pitch);
  j.median = med;
  j.step = med - j.base;
  const double nw = static_cast<double>(win.size());
  const double sw = robust_scale(win, med);
  double var = (sw * sw + var_w / nw) / nw;
  if (has_history) {
    const double nh = static_cast<double>(hist.size());
    const double sh = robust_scale(hist, j.base);
    var += (sh * sh + var_h / nh) / nh;
  }
  j.sigma = std::sqrt(var);
  j.judged = worst <= opt_.steady_tolerance && comparable;
  j.stepped = j.judged && std::abs(j.step) >= opt_.min_step;
  return j;
}

// When the new level began: after the last frame before the window that was still at the old one
// (frames at neither, a bump's, are passed over).
size_t MountingWatch::change_start(size_t begin, const bool stepped[2], const double bases[2],
                                   const double medians[2]) const {
  size_t first = begin;
  int at_old = 0;  // consecutive frames at the old level (a bump passing through it is not one)
  for (size_t i = begin; i-- > 0 && at_old < 5;) {
    bool old = true;
    for (int angle = 0; angle < 2; ++angle)
      if (stepped[angle] && (samples_[i].t < since_[angle] ||
                             std::abs(residual(samples_[i], angle) - bases[angle]) > opt_.steady_tolerance))
        old = false;
    at_old = old ? at_old + 1 : 0;
    const int a = stepped[0] ? 0 : 1;
    if (std::abs(residual(samples_[i], a) - medians[a]) <= opt_.steady_tolerance) first = i;
  }
  return first;
}

std::optional<MountingChange> MountingWatch::test() {
  // The window: the most recent samples over window_metres and window_seconds.
  const Sample& last = samples_.back();
  size_t begin = samples_.size();
  while (begin > 0) {
    --begin;
    if (last.s - samples_[begin].s >= opt_.window_metres && last.t - samples_[begin].t >= opt_.window_seconds) break;
    if (begin == 0) return std::nullopt;  // not yet a whole window
  }
  // The history before it: at most history_seconds, and per angle since its last change.
  while (samples_.front().t <
         std::max(std::min({since_[0], since_[1], since_[2], since_[3]}), samples_[begin].t - opt_.history_seconds)) {
    samples_.pop_front();
    --begin;
  }
  fit_lean(begin);

  MountingChange change;
  bool stepped[2] = {false, false};  // held a new level by min_step at least
  bool judged[2] = {false, false};   // steady and comparable: its step is measured
  double steps[2] = {0.0, 0.0}, medians[2] = {0.0, 0.0}, bases[2] = {0.0, 0.0};
  for (int angle = 0; angle < 2; ++angle) {
    const AngleJudgement j = judge_angle(angle, begin);
    bases[angle] = j.base;
    medians[angle] = j.median;
    steps[angle] = j.step;
    change.sigma(angle) = j.sigma;
    judged[angle] = j.judged;
    stepped[angle] = j.stepped;
  }
  if (std::optional<MountingChange> r = refine(begin, judged, medians, change.sigma)) return r;
  if (!stepped[0] && !stepped[1]) return test_height(bases);

  const size_t first = change_start(begin, stepped, bases, medians);
  change.time = samples_[first].t;
  change.detected_time = last.t;
  last_bases_[0] = bases[0];
  last_bases_[1] = bases[1];

  // The roll's step and the lean's slope together (roll = c + k omega + step after the change, by
  // least squares over the frames since the roll's last change): a window in a turn the history
  // did not drive would otherwise carry the slope's error times the yaw rate.
  if (judged[0]) joint_roll_step(first, &steps[0], &change.sigma(0));
  // An angle that the window could not judge keeps its level and its history: unchanged.
  change.step.roll = judged[0] ? steps[0] : 0.0;
  change.step.pitch = judged[1] ? steps[1] : 0.0;
  measure_yaw(begin, first, &change);
  for (int angle = 0; angle < 2; ++angle) {
    if (!judged[angle]) continue;
    (angle == 0 ? level_.roll : level_.pitch) = medians[angle];
    since_[angle] = change.time;
  }
  // The distances tracked before it was found were scaled by the turned camera's height error, and
  // the directions turned by its yaw.
  since_[2] = change.detected_time;
  if (std::isfinite(change.sigma_yaw)) since_[3] = change.detected_time;
  return change;
}

void MountingWatch::joint_roll_step(size_t first, double* step, double* sigma) {
  // Least squares, then once more without the frames beyond 3 robust sigma of the first fit (the
  // frames where a turn begins or ends, whose roll lags the yaw rate of their interval).
  std::vector<size_t> used;
  for (size_t i = 0; i < samples_.size(); ++i)
    if (samples_[i].t >= since_[0]) used.push_back(i);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Constant(NAN);
  auto x_of = [&](size_t i) { return Eigen::Vector3d(1.0, samples_[i].w, i >= first ? 1.0 : 0.0); };
  for (int pass = 0; pass < 2; ++pass) {
    if (used.size() < 20) return;
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (size_t i : used) {
      A += x_of(i) * x_of(i).transpose();
      b += x_of(i) * samples_[i].roll;
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-9)) return;
    p = ldlt.solve(b);
    std::vector<double> r;
    for (size_t i : used) r.push_back(samples_[i].roll - x_of(i).dot(p));
    const double scale = std::max(robust_scale(r, 0.0), 0.02 * M_PI / 180.0);
    double ss = 0.0;
    for (double v : r) ss += v * v;
    cov = ss / static_cast<double>(used.size() - 3) * ldlt.solve(Eigen::Matrix3d::Identity());
    std::vector<size_t> kept;
    for (size_t j = 0; j < used.size(); ++j)
      if (std::abs(r[j]) <= 3.0 * scale) kept.push_back(used[j]);
    used = kept;
  }
  if (!p.allFinite() || !(cov(2, 2) >= 0.0)) return;
  *step = p(2);
  *sigma = std::sqrt(cov(2, 2));
  if (std::sqrt(cov(1, 1)) < 0.01) {  // the slope known to 0.01 (deg per deg/s): the fit's from now on
    k_roll_ = p(1);
    lean_known_ = true;
  }
}

void MountingWatch::measure_yaw(size_t begin, size_t first, MountingChange* change) const {
  // The turn about the vertical that came with the tilt (a camera tilted forward and knocked about
  // its own axis turns about the body's vertical too): the direction of travel tracked in the
  // window against its history before the change. The mounting's yaw changed by d turns the
  // tracked direction by -d.
  std::vector<double> win, hist;
  for (size_t i = begin; i < samples_.size(); ++i)
    if (std::isfinite(samples_[i].heading)) win.push_back(samples_[i].heading);
  for (size_t i = 0; i < first; ++i)
    if (std::isfinite(samples_[i].heading) && samples_[i].t >= since_[3]) hist.push_back(samples_[i].heading);
  if (win.size() < 5 || hist.size() < 10) return;
  const double mw = median(win), mh = median(hist);
  const double sw = robust_scale(win, mw), sh = robust_scale(hist, mh);
  change->dyaw = -(mw - mh);
  change->sigma_yaw = std::sqrt(sw * sw / static_cast<double>(win.size()) + sh * sh / static_cast<double>(hist.size()));
}

std::optional<MountingChange> MountingWatch::refine(size_t begin, const bool judged[2], const double medians[2],
                                                    const Eigen::Vector2d& sigma) {
  if (!(refining_[0] || refining_[1]) || samples_[begin].t < refine_after_) return std::nullopt;
  MountingChange r;
  bool any = false;
  for (int angle = 0; angle < 2; ++angle) {
    if (!refining_[angle] || !judged[angle]) continue;
    refining_[angle] = false;
    const double step = medians[angle] - refine_base_[angle];
    if (!(std::abs(step) >= opt_.min_refinement && std::abs(step) >= 3.0 * sigma(angle))) continue;
    (angle == 0 ? r.step.roll : r.step.pitch) = step;
    r.sigma(angle) = sigma(angle);
    (angle == 0 ? level_.roll : level_.pitch) = medians[angle];
    since_[angle] = refine_after_;
    any = true;
  }
  if (!any) return std::nullopt;
  r.refinement = true;
  r.time = refine_time_;
  r.detected_time = samples_.back().t;
  since_[2] = r.detected_time;
  return r;
}

double MountingWatch::residual(const Sample& s, int angle) const {
  return angle == 0 ? s.roll - k_roll_ * s.w : s.pitch;
}

std::optional<MountingChange> MountingWatch::test_height(const double levels[2]) {
  if (!(opt_.height > 0.0)) return std::nullopt;
  // The window: the most recent height_window_metres of wheel travel, every frame with odometry.
  const size_t n = samples_.size();
  size_t begin = n;
  double odo = 0.0;
  while (begin > 0 && odo < opt_.height_window_metres) {
    const Sample& s = samples_[--begin];
    if (!std::isfinite(s.odo) || s.t < since_[2]) return std::nullopt;
    odo += s.odo;
  }
  if (odo < opt_.height_window_metres) return std::nullopt;
  // Only while the attitude holds its level at every frame of the window: a turned camera not yet
  // found shows as a height (the local plane turns the body about the ground, which moves the
  // camera). A bump in the window waits for the next stretch without one. The roll only once the
  // lean's slope is known (before, a turn's lean would hold the test off).
  for (size_t i = begin; i < n; ++i)
    for (int angle = lean_known_ ? 0 : 1; angle < 2; ++angle)
      if (!(std::abs(residual(samples_[i], angle) - levels[angle]) < 0.5 * opt_.min_step)) return std::nullopt;
  // The ratio of distances over [a, b) and its variance (the frames' scatter about it), over the
  // frames that moved (a frame standing still adds the tracker's noise to the distance tracked and
  // nothing to the wheels').
  auto counts = [&](const Sample& s) { return s.odo >= opt_.height_min_travel && s.t >= since_[2]; };
  struct Ratio {
    double r = NAN, var = NAN, odo = 0.0;
  };
  auto ratio = [&](size_t a, size_t b) {
    Ratio q;
    double vis = 0.0;
    for (size_t i = a; i < b; ++i)
      if (counts(samples_[i])) {
        vis += samples_[i].vis;
        q.odo += samples_[i].odo;
      }
    if (!(q.odo > 0.0)) return q;
    q.r = vis / q.odo;
    double ss = 0.0;
    for (size_t i = a; i < b; ++i)
      if (counts(samples_[i])) ss += std::pow(samples_[i].vis - q.r * samples_[i].odo, 2);
    q.var = ss / (q.odo * q.odo);
    return q;
  };
  const Ratio hist = ratio(0, begin);
  if (hist.odo < opt_.height_history_metres) return std::nullopt;
  const Ratio win = ratio(begin, n);
  size_t mid = begin;
  for (double o = 0.0; mid < n && o < 0.5 * win.odo; ++mid) o += samples_[mid].odo;
  const Ratio first = ratio(begin, mid), second = ratio(mid, n);
  const double d = win.r / hist.r - 1.0;
  const double sigma_d = std::sqrt(win.var / (win.r * win.r) + hist.var / (hist.r * hist.r));
  const bool halves = (first.r / hist.r - 1.0) * d >= 0.25 * d * d && (second.r / hist.r - 1.0) * d >= 0.25 * d * d;
  // r = z_mounting / z_true (times the wheels' scale): the true height z r_before / r_after.
  if (!(std::abs(opt_.height * d) >= opt_.min_height_step && std::abs(d) >= opt_.height_sigmas * sigma_d && halves))
    return std::nullopt;
  // When: the split of the frames since the last change that best tells two ratios apart; the
  // change is measured across it.
  MountingChange change;
  change.detected_time = samples_.back().t;
  double best = -1.0, vis_a = 0.0, odo_a = 0.0, vis_all = 0.0, odo_all = 0.0;
  size_t split = begin;
  for (const Sample& s : samples_)
    if (counts(s)) {
      vis_all += s.vis;
      odo_all += s.odo;
    }
  for (size_t i = 0; i < n; ++i) {
    const Sample& s = samples_[i];
    if (!counts(s)) continue;
    const double odo_b = odo_all - odo_a;
    // Each side long enough to measure a ratio on.
    if (odo_a >= 0.5 * opt_.height_history_metres && odo_b >= 0.5 * opt_.height_window_metres) {
      const double score = std::abs(vis_a / odo_a - (vis_all - vis_a) / odo_b) * std::sqrt(odo_a * odo_b / odo_all);
      if (score > best) {
        best = score;
        split = i;
      }
    }
    vis_a += s.vis;
    odo_a += s.odo;
  }
  const Ratio before = ratio(0, split), after = ratio(split, n);
  change.time = samples_[split].t;
  change.dz = opt_.height * (before.r / after.r - 1.0);
  change.sigma_z = opt_.height * before.r / after.r *
                   std::sqrt(after.var / (after.r * after.r) + before.var / (before.r * before.r));
  since_[2] = change.time;
  return change;
}

}  // namespace planarvo::track
