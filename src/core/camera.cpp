#include "core/camera.h"

#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Dense>

#include "core/error.h"
#include "kernels/common/distortion.h"

namespace planarvo {

Eigen::Matrix3d CameraModel::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

Eigen::Vector2d CameraModel::distort(const Eigen::Vector2d& xn) const {
  Eigen::Vector2d xd;
  pv_distort_double(xn.x(), xn.y(), k1, k2, p1, p2, k3, &xd.x(), &xd.y());
  return xd;
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& xd) const {
  if (!has_distortion()) return xd;
  // Newton on distort(x) = xd, started at xd, with the analytic Jacobian of the forward model.
  Eigen::Vector2d x = xd;
  for (int it = 0; it < 50; ++it) {
    const double u = x.x(), v = x.y();
    const double r2 = u * u + v * v;
    const double radial = pv_radial_double(r2, k1, k2, k3);
    const double dradial = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);  // d radial / d r2
    // The Jacobian is symmetric, [a b; b c], and near the identity inside the model's domain:
    // its inverse in closed form (an LU of a 2x2 matrix cost more than the rest of the step).
    const double a = radial + 2.0 * u * u * dradial + 2.0 * p1 * v + 6.0 * p2 * u;
    const double b = 2.0 * u * v * dradial + 2.0 * p1 * u + 2.0 * p2 * v;
    const double c = radial + 2.0 * v * v * dradial + 6.0 * p1 * v + 2.0 * p2 * u;
    const Eigen::Vector2d r = distort(x) - xd;
    const double det = a * c - b * b;
    const Eigen::Vector2d step = Eigen::Vector2d(c * r.x() - b * r.y(), a * r.y() - b * r.x()) / det;
    x -= step;
    if (step.squaredNorm() < 1e-30) break;
  }
  return x;
}

Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& X) const {
  const Eigen::Vector2d d = distort(Eigen::Vector2d(X.x() / X.z(), X.y() / X.z()));
  return {fx * d.x() + cx, fy * d.y() + cy};
}

Eigen::Vector2d CameraModel::unproject(const Eigen::Vector2d& pixel) const {
  return undistort(Eigen::Vector2d((pixel.x() - cx) / fx, (pixel.y() - cy) / fy));
}

double CameraModel::row_time(double r) const {
  const double read = height > 1 ? r / (height - 1) * rolling_shutter_readout : 0.0;
  return read - 0.5 * exposure_time;
}

void CameraModel::validate(const char* what) const {
  const std::string where(what);
  if (width <= 0 || height <= 0)
    throw_invalid_input(where + ": image_width and image_height must be positive (got " +
                        std::to_string(width) + "x" + std::to_string(height) + ")");
  for (double v : {fx, fy, cx, cy, k1, k2, p1, p2, k3})
    if (!std::isfinite(v)) throw_invalid_input(where + ": camera parameters contain NaN or inf");
  if (!(fx > 0) || !(fy > 0))
    throw_invalid_input(where + ": focal lengths fx, fy must be positive");
  if (!std::isfinite(rolling_shutter_readout) || rolling_shutter_readout < 0) {
    char got[32];
    std::snprintf(got, sizeof got, "%g", rolling_shutter_readout);
    throw_invalid_input(where + ": rolling_shutter_readout must be a finite number of seconds >= 0 (got " +
                        got + ")");
  }
  if (!std::isfinite(exposure_time) || exposure_time < 0) {
    char got[32];
    std::snprintf(got, sizeof got, "%g", exposure_time);
    throw_invalid_input(where + ": exposure_time must be a finite number of seconds >= 0 (got " + got + ")");
  }
  if (roi.width != 0 || roi.height != 0) {
    const std::string r = "region of interest [" + std::to_string(roi.x) + ", " + std::to_string(roi.y) + ", " +
                          std::to_string(roi.width) + ", " + std::to_string(roi.height) + "] (x, y, width, height)";
    if (roi.width < kMinRegionSide || roi.height < kMinRegionSide)
      throw_invalid_input(where + ": the " + r + " must be at least " + std::to_string(kMinRegionSide) +
                          " pixels on a side");
    if (roi.x < 0 || roi.y < 0 || roi.width > width - roi.x || roi.height > height - roi.y)
      throw_invalid_input(where + ": the " + r + " is not inside the " + std::to_string(width) + "x" +
                          std::to_string(height) + " image");
  }
}

}  // namespace planarvo
