// Pieces of the graph calibrations (calibration.h) that are not graphs: the closed-form starts of
// both methods, the shape of a trajectory (for saying why something is unobservable), and the
// one-dimensional direction prior (eq. 31) for y. Internal to src/graph.
#pragma once
#include <array>
#include <vector>

#include "core/se2.h"

namespace planarvo::graph::calibration_detail {

// Odometry method (5.2.1). The calibration T = SE2(x, y, γ) and scale h satisfy
// m_r · T = T · S_h(m_s) for every interval (docs/conventions.md: m_r = T·S_h(m_s)·T⁻¹). Its
// rotation part holds for any T (planar rotations commute: the angles only say θ_r = θ_s); its
// translation part is
//     (I − R(θ_r)) p + h R(γ) t_s = t_r,
// linear in w = (x, y, a, b) with (a, b) = h (cos γ, sin γ), since h R(γ) t_s = [[t_x, −t_y],
// [t_y, t_x]] (a, b). Least squares over all intervals (reweighted with a Cauchy weight on the
// residuals' own robust scale, against gross errors) gives (x, y, a, b), h = |(a, b)| and
// γ = atan2(b, a). With h fixed, p is eliminated and the reduced quadratic in (a, b) is minimised
// on the circle |(a, b)| = h (a fine grid on γ, then Newton). Exact on noise-free data.
// `robot` are the odometry motions; returns (x, y, h, γ).
std::array<double, 4> odometry_closed_form(const std::vector<SE2>& robot,
                                           const std::vector<SE2>& sensor, bool fix_scale,
                                           double fixed_scale);

// Nonholonomic method (5.2.2), arc form: with n = (−sin(θ/2), cos(θ/2)),
//     e = n · t(m_r) = −2 sin(θ/2) x + a (cos(θ/2) t_y − sin(θ/2) t_x)
//                                      + b (cos(θ/2) t_x + sin(θ/2) t_y),
// (a, b) = h (cos γ, sin γ): y drops out (n · (I − R(θ)) p = −2 sin(θ/2) x) and e is homogeneous
// linear in (x, a, b). Eliminating x leaves a 2×2 quadratic form in (a, b) whose smallest
// eigenvector on |(a, b)| = h is the answer, up to its sign: the two branches (x, γ) and
// (−x, γ + π). Reweighted against gross errors as above. Returns one branch (x, γ).
std::array<double, 2> nonholonomic_closed_form(const std::vector<SE2>& sensor, double scale);

// Whether a set of sensor motions (in the sensor frame, with standard deviations of their
// translations and angles) is degenerate for calibration, to word the reason:
//   straight_only: the rotations are at the noise level;
//   one_circle:    every motion is a rotation about one and the same point (one circle at one
//                  curvature, turning in place included): its translations are explained, to the
//                  noise level or to 1e-3 of their size, by t = (I − R(θ)) c for a single c.
struct TrajectoryShape {
  bool straight_only = false;
  bool one_circle = false;
};
TrajectoryShape classify_trajectory(const std::vector<SE2>& sensor,
                                    const std::vector<double>& sigma_t,
                                    const std::vector<double>& sigma_theta);

// The direction prior (eq. 31) as a function of y alone, x, γ and h given: the robot's forward
// motion over an interval is m_r,x = α + β y (β = sin θ), and the prior's residual is
// α + β y for label 0, min(α + β y, 0) for +1, max(α + β y, 0) for −1, weighted by the inverse
// variance of m_r,x. The cost C(y) = Σ w r² is convex and piecewise quadratic.
struct PriorTerm {
  double alpha = 0.0, beta = 0.0, weight = 0.0;
  int label = 0;
};
// Whether a term's residual r = α + β y counts: always for label 0, for +1 where negative, for
// −1 where positive.
inline bool prior_term_active(const PriorTerm& t, double r) {
  return t.label == 0 || (t.label > 0 ? r < 0.0 : r > 0.0);
}
double direction_prior_cost(const std::vector<PriorTerm>& terms, double y);
// The minimising set [argmin_lo, argmin_hi] of C (one point when labels 0 or contradicting
// labels pin y; the interval the ±1 labels leave otherwise), its midpoint as the estimate, and
// the region where C ≤ C_min + delta_cost (the one-sigma region for delta_cost 1: for a
// quadratic C exactly ± the standard deviation). Bounds beyond ±1e4 are ±infinity.
struct PriorSolution {
  double argmin_lo = 0.0, argmin_hi = 0.0;
  double estimate = 0.0;
  double region_lo = 0.0, region_hi = 0.0;
  double cost_min = 0.0;
};
PriorSolution solve_direction_prior(const std::vector<PriorTerm>& terms, double delta_cost);

}  // namespace planarvo::graph::calibration_detail
