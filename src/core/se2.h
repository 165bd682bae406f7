// SE(2): planar rigid motion (x, y, theta), the robot's pose and relative motion
// (docs/conventions.md: relative motion between frames k and k+1 is T_k^-1 * T_{k+1}).
#pragma once
#include <cmath>
#include <Eigen/Core>

namespace planarvo {

// The farthest a position (metres from its frame's origin) may lie in any input: a robot's drive
// or a map is far smaller, and beyond it a double keeps less than 0.1 µm, so a value past it is
// a corrupt file or a unit mistake, refused where it is read.
inline constexpr double kMaxPositionMetres = 1e6;

// Wraps an angle to (-pi, pi].
inline double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

struct SE2 {
  double x = 0.0, y = 0.0, theta = 0.0;

  SE2() = default;
  SE2(double x_, double y_, double theta_) : x(x_), y(y_), theta(theta_) {}

  SE2 operator*(const SE2& b) const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {x + c * b.x - s * b.y, y + s * b.x + c * b.y, wrap_angle(theta + b.theta)};
  }
  SE2 inverse() const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {-c * x - s * y, s * x - c * y, wrap_angle(-theta)};
  }
  Eigen::Vector2d operator*(const Eigen::Vector2d& p) const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {x + c * p.x() - s * p.y(), y + s * p.x() + c * p.y()};
  }
  Eigen::Matrix3d matrix() const {
    const double c = std::cos(theta), s = std::sin(theta);
    Eigen::Matrix3d m;
    m << c, -s, x, s, c, y, 0, 0, 1;
    return m;
  }
  // The 4x4 rigid transform of this motion raised into SE(3) on the plane z = 0 (paper eq. 4).
  Eigen::Matrix4d matrix3d() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    const double c = std::cos(theta), s = std::sin(theta);
    m(0, 0) = c; m(0, 1) = -s; m(1, 0) = s; m(1, 1) = c;
    m(0, 3) = x; m(1, 3) = y;
    return m;
  }
  Eigen::Vector3d vector() const { return {x, y, theta}; }
  // The adjoint on se(2) = (vx, vy, omega): T exp(xi) T^-1 = exp(Ad_T xi).
  Eigen::Matrix3d adjoint() const {
    const double c = std::cos(theta), s = std::sin(theta);
    Eigen::Matrix3d A;
    A << c, -s, y, s, c, -x, 0, 0, 1;
    return A;
  }

  // Exponential map of se(2): (vx, vy, omega) integrated for unit time, i.e. the constant-
  // velocity arc. exp(log(T)) == T.
  static SE2 exp(const Eigen::Vector3d& xi) {
    double a, b;
    arc_coefficients(xi.z(), &a, &b);
    return {a * xi.x() - b * xi.y(), b * xi.x() + a * xi.y(), wrap_angle(xi.z())};
  }
  Eigen::Vector3d log() const {
    double a, b;
    arc_coefficients(theta, &a, &b);
    const double det = a * a + b * b;
    return {(a * x + b * y) / det, (-b * x + a * y) / det, theta};
  }

 private:
  // sin(w)/w and (1 - cos(w))/w, with their series near zero: the translation of exp((v, w)) is
  // [[a, -b], [b, a]] v.
  static void arc_coefficients(double w, double* a, double* b) {
    if (std::abs(w) < 1e-6) {
      *a = 1.0 - w * w / 6.0;
      *b = w / 2.0 - w * w * w / 24.0;
    } else {
      *a = std::sin(w) / w;
      *b = (1.0 - std::cos(w)) / w;
    }
  }
};

// Pose interpolation between two samples, linear in x, y and theta (docs/formats.md), the angle
// taken along the shorter way.
inline SE2 interpolate_linear(const SE2& a, const SE2& b, double f) {
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y),
          wrap_angle(a.theta + f * wrap_angle(b.theta - a.theta))};
}

}  // namespace planarvo
