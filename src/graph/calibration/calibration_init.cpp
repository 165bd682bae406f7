#include "graph/calibration/calibration_init.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace planarvo::graph::calibration_detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Cauchy weights 1 / (1 + (r / c)²), c = 3 × the residuals' robust scale (1.4826 · median |r|),
// kept above `floor` so that exact data (all residuals at rounding level) keep weight 1.
void cauchy_weights(const std::vector<double>& r, double floor, std::vector<double>& w) {
  std::vector<double> a(r.size());
  for (size_t i = 0; i < r.size(); ++i) a[i] = std::abs(r[i]);
  const double c = 3.0 * std::max(1.4826 * median(a), floor);
  for (size_t i = 0; i < r.size(); ++i) w[i] = 1.0 / (1.0 + (a[i] / c) * (a[i] / c));
}

// The pseudo-inverse of a small symmetric positive semi-definite A: directions with less than
// 1e-12 of its largest eigenvalue (no information: driving straight leaves x, y free) get 0
// instead of a blow-up, so the start is the minimum-norm solution there.
template <int N>
Eigen::Matrix<double, N, N> pseudo_inverse(const Eigen::Matrix<double, N, N>& A) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(A);
  const auto& l = es.eigenvalues();
  const double top = std::max(l.maxCoeff(), 0.0);
  Eigen::Matrix<double, N, 1> inv;
  for (int i = 0; i < N; ++i) inv[i] = top > 0.0 && l[i] > 1e-12 * top ? 1.0 / l[i] : 0.0;
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

// min over γ of f(γ) = h² cᵀMc − 2h gᵀc, c = (cos γ, sin γ): a grid, then Newton.
double minimise_on_circle(const Eigen::Matrix2d& M, const Eigen::Vector2d& g, double h) {
  auto f = [&](double a) {
    const Eigen::Vector2d c(std::cos(a), std::sin(a));
    return h * h * c.dot(M * c) - 2.0 * h * g.dot(c);
  };
  double best = 0.0, fbest = f(0.0);
  constexpr int kGrid = 720;
  for (int k = 1; k < kGrid; ++k) {
    const double a = 2.0 * M_PI * k / kGrid;
    const double fa = f(a);
    if (fa < fbest) best = a, fbest = fa;
  }
  // Newton on the derivative alone from the grid's best (within 0.25° of the minimum): values of
  // f near its minimum differ at rounding level, comparing them would stop at √ε.
  for (int it = 0; it < 30; ++it) {
    const Eigen::Vector2d c(std::cos(best), std::sin(best)), d(-std::sin(best), std::cos(best));
    const double d1 = 2.0 * h * h * c.dot(M * d) - 2.0 * h * g.dot(d);
    const double d2 = 2.0 * h * h * (d.dot(M * d) - c.dot(M * c)) + 2.0 * h * g.dot(c);
    if (!(d2 > 0.0)) break;
    const double step = std::clamp(-d1 / d2, -0.01, 0.01);
    best += step;
    if (std::abs(step) < 1e-15) break;
  }
  return wrap_angle(best);
}

}  // namespace

std::array<double, 4> odometry_closed_form(const std::vector<SE2>& robot,
                                           const std::vector<SE2>& sensor, bool fix_scale,
                                           double fixed_scale) {
  const size_t n = robot.size();
  std::vector<double> w(n, 1.0), res(n, 0.0);
  std::vector<double> travel(n);
  for (size_t i = 0; i < n; ++i) travel[i] = std::hypot(robot[i].x, robot[i].y);
  const double floor = 1e-9 * std::max(median(travel), 1e-12);
  Eigen::Vector4d sol(0.0, 0.0, fix_scale ? fixed_scale : 1.0, 0.0);  // x, y, a, b
  for (int iteration = 0; iteration < 8; ++iteration) {
    Eigen::Matrix4d N = Eigen::Matrix4d::Zero();
    Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
    for (size_t i = 0; i < n; ++i) {
      const double c = std::cos(robot[i].theta), s = std::sin(robot[i].theta);
      const double tx = sensor[i].x, ty = sensor[i].y;
      const Eigen::Vector4d r1(1.0 - c, s, tx, -ty), r2(-s, 1.0 - c, ty, tx);
      N += w[i] * (r1 * r1.transpose() + r2 * r2.transpose());
      rhs += w[i] * (r1 * robot[i].x + r2 * robot[i].y);
    }
    if (!fix_scale) {
      sol = pseudo_inverse<4>(N) * rhs;
    } else {
      // Eliminate p = Npp⁻¹ (bp − Npq q); the rest is a quadratic in q on |q| = h.
      const Eigen::Matrix2d Npp_inv = pseudo_inverse<2>(Eigen::Matrix2d(N.topLeftCorner<2, 2>()));
      const Eigen::Matrix2d Npq = N.topRightCorner<2, 2>();
      const Eigen::Matrix2d M = N.bottomRightCorner<2, 2>() - Npq.transpose() * Npp_inv * Npq;
      const Eigen::Vector2d g = rhs.tail<2>() - Npq.transpose() * Npp_inv * rhs.head<2>();
      const double gamma = minimise_on_circle(M, g, fixed_scale);
      const Eigen::Vector2d q = fixed_scale * Eigen::Vector2d(std::cos(gamma), std::sin(gamma));
      sol << Npp_inv * (rhs.head<2>() - Npq * q), q;
    }
    for (size_t i = 0; i < n; ++i) {
      const double c = std::cos(robot[i].theta), s = std::sin(robot[i].theta);
      const double tx = sensor[i].x, ty = sensor[i].y;
      const double e1 = (1.0 - c) * sol[0] + s * sol[1] + tx * sol[2] - ty * sol[3] - robot[i].x;
      const double e2 = -s * sol[0] + (1.0 - c) * sol[1] + ty * sol[2] + tx * sol[3] - robot[i].y;
      res[i] = std::hypot(e1, e2);
    }
    cauchy_weights(res, floor, w);
  }
  double h = fix_scale ? fixed_scale : std::hypot(sol[2], sol[3]);
  if (!(h > 0.0) || !std::isfinite(h)) h = 1.0;
  const double gamma = std::atan2(sol[3], sol[2]);
  return {sol[0], sol[1], h, std::isfinite(gamma) ? gamma : 0.0};
}

std::array<double, 2> nonholonomic_closed_form(const std::vector<SE2>& sensor, double scale) {
  const size_t n = sensor.size();
  std::vector<Eigen::Vector3d> rows(n);
  std::vector<double> travel(n);
  for (size_t i = 0; i < n; ++i) {
    const double sh = std::sin(0.5 * sensor[i].theta), ch = std::cos(0.5 * sensor[i].theta);
    const double tx = sensor[i].x, ty = sensor[i].y;
    rows[i] << -2.0 * sh, ch * ty - sh * tx, ch * tx + sh * ty;
    travel[i] = scale * std::hypot(tx, ty);
  }
  const double floor = 1e-9 * std::max(median(travel), 1e-12);
  std::vector<double> w(n, 1.0), res(n, 0.0);
  double x = 0.0, gamma = 0.0;
  for (int iteration = 0; iteration < 8; ++iteration) {
    Eigen::Matrix3d N = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < n; ++i) N += w[i] * rows[i] * rows[i].transpose();
    // Eliminate x (when anything constrains it: no rotation leaves it free, at 0).
    const double nxx = N(0, 0);
    const bool has_x = nxx > 1e-12 * std::max(N.diagonal().maxCoeff(), 1e-300);
    Eigen::Matrix2d M = N.bottomRightCorner<2, 2>();
    if (has_x) M -= N.block<2, 1>(1, 0) * N.block<1, 2>(0, 1) / nxx;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(M);
    const Eigen::Vector2d q = scale * es.eigenvectors().col(0);
    x = has_x ? -N.block<1, 2>(0, 1).dot(q) / nxx : 0.0;
    gamma = std::atan2(q[1], q[0]);
    for (size_t i = 0; i < n; ++i) res[i] = rows[i].dot(Eigen::Vector3d(x, q[0], q[1]));
    cauchy_weights(res, floor, w);
  }
  return {x, gamma};
}

TrajectoryShape classify_trajectory(const std::vector<SE2>& sensor,
                                    const std::vector<double>& sigma_t,
                                    const std::vector<double>& sigma_theta) {
  TrajectoryShape shape;
  const size_t n = sensor.size();
  if (n == 0) return shape;
  double rot = 0.0, max_rot = 0.0;
  for (size_t i = 0; i < n; ++i) {
    rot += std::pow(sensor[i].theta / sigma_theta[i], 2);
    max_rot = std::max(max_rot, std::abs(sensor[i].theta));
  }
  if (rot <= 9.0 * static_cast<double>(n) || max_rot <= 1e-9) {
    shape.straight_only = true;
    return shape;
  }
  // One centre c with t = (I − R) c: (I − R)ᵀ(I − R) = 2 (1 − cos θ) I.
  double a = 0.0, size = 0.0;
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double w = 1.0 / (sigma_t[i] * sigma_t[i]);
    const double c = std::cos(sensor[i].theta), s = std::sin(sensor[i].theta);
    Eigen::Matrix2d IR;
    IR << 1.0 - c, s, -s, 1.0 - c;
    const Eigen::Vector2d t(sensor[i].x, sensor[i].y);
    a += w * 2.0 * (1.0 - c);
    b += w * IR.transpose() * t;
    size += w * t.squaredNorm();
  }
  const Eigen::Vector2d centre = b / a;
  double resid = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double w = 1.0 / (sigma_t[i] * sigma_t[i]);
    const double c = std::cos(sensor[i].theta), s = std::sin(sensor[i].theta);
    Eigen::Matrix2d IR;
    IR << 1.0 - c, s, -s, 1.0 - c;
    resid += w * (Eigen::Vector2d(sensor[i].x, sensor[i].y) - IR * centre).squaredNorm();
  }
  shape.one_circle = resid <= 4.0 * 2.0 * static_cast<double>(n) || resid <= 1e-6 * size;
  return shape;
}

namespace {

double slope(const std::vector<PriorTerm>& terms, double y) {
  double d = 0.0;
  for (const PriorTerm& t : terms) {
    const double r = t.alpha + t.beta * y;
    if (prior_term_active(t, r)) d += 2.0 * t.weight * t.beta * r;
  }
  return d;
}

// Bisection for the boundary of a monotone predicate on [lo, hi] (pred(lo) false, pred(hi) true).
template <class Pred>
double boundary(double lo, double hi, Pred pred) {
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (pred(mid) ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double direction_prior_cost(const std::vector<PriorTerm>& terms, double y) {
  double c = 0.0;
  for (const PriorTerm& t : terms) {
    const double r = t.alpha + t.beta * y;
    if (prior_term_active(t, r)) c += t.weight * r * r;
  }
  return c;
}

PriorSolution solve_direction_prior(const std::vector<PriorTerm>& terms, double delta_cost) {
  constexpr double L = 1e4;
  PriorSolution s;
  // C is convex and C¹: its slope is non-decreasing and exactly 0 on a flat bottom.
  s.argmin_lo = slope(terms, -L) >= 0.0 ? -kInf
                : slope(terms, L) < 0.0 ? kInf
                                        : boundary(-L, L, [&](double y) { return slope(terms, y) >= 0.0; });
  s.argmin_hi = slope(terms, L) <= 0.0 ? kInf
                : slope(terms, -L) > 0.0 ? -kInf
                                         : boundary(-L, L, [&](double y) { return slope(terms, y) > 0.0; });
  if (std::isfinite(s.argmin_lo) && std::isfinite(s.argmin_hi) && s.argmin_hi < s.argmin_lo)
    s.argmin_hi = s.argmin_lo = 0.5 * (s.argmin_lo + s.argmin_hi);  // a point, up to rounding
  if (std::isfinite(s.argmin_lo) && std::isfinite(s.argmin_hi))
    s.estimate = 0.5 * (s.argmin_lo + s.argmin_hi);
  else if (std::isfinite(s.argmin_lo))
    s.estimate = s.argmin_lo;
  else if (std::isfinite(s.argmin_hi))
    s.estimate = s.argmin_hi;
  else
    s.estimate = 0.0;
  s.cost_min = direction_prior_cost(terms, s.estimate);
  const double level = s.cost_min + delta_cost;
  const double left = std::isfinite(s.argmin_lo) ? s.argmin_lo : s.estimate;
  const double right = std::isfinite(s.argmin_hi) ? s.argmin_hi : s.estimate;
  s.region_lo = !std::isfinite(s.argmin_lo) || direction_prior_cost(terms, -L) <= level
                    ? -kInf
                    : boundary(-L, left, [&](double y) { return direction_prior_cost(terms, y) <= level; });
  s.region_hi = !std::isfinite(s.argmin_hi) || direction_prior_cost(terms, L) <= level
                    ? kInf
                    : boundary(right, L, [&](double y) { return direction_prior_cost(terms, y) > level; });
  return s;
}

}  // namespace planarvo::graph::calibration_detail
