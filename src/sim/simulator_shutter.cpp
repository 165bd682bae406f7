// What a real camera sees of the moving ground: each row at its own read time (rolling
// shutter) and averaged over the exposure before it (motion blur). See SIMULATOR.md,
// "Rolling shutter and exposure", and docs/conventions.md for the stamp convention.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "core/error.h"
#include "sim/simulator.h"

namespace planarvo::sim {

SE2 pose_at(const Trajectory& tr, double t) {
  if (tr.pose.empty() || tr.t.size() != tr.pose.size())
    throw_invalid_argument("pose_at: the trajectory has no poses, or not one per time");
  if (!(t > tr.t.front())) return tr.pose.front();  // standing before the first frame (and NaN)
  // The last frame at or before t.
  const size_t k = static_cast<size_t>(std::upper_bound(tr.t.begin(), tr.t.end(), t) - tr.t.begin()) - 1;
  const double dt = t - tr.t[k];
  if (dt == 0.0) return tr.pose[k];
  if (tr.velocity.empty()) return tr.pose[k];  // one frame: nothing moves
  const Eigen::Vector2d& vw = tr.velocity[std::min(k, tr.velocity.size() - 1)];
  return tr.pose[k] * SE2::exp(Eigen::Vector3d(vw.x() * dt, 0.0, vw.y() * dt));
}

double image_speed(const Options& o, const Eigen::Vector2d& velocity) {
  if (velocity.x() == 0.0 && velocity.y() == 0.0) return 0.0;
  const CameraModel& cam = o.camera;
  const Eigen::Matrix4d T_vc = o.extrinsics.T_vc();
  const Eigen::Matrix3d R = T_vc.topLeftCorner<3, 3>();
  const Eigen::Vector3d C = T_vc.topRightCorner<3, 1>();
  // The ground point seen at a pixel, as the camera sees it after the robot moved by
  // exp(s (v, 0, omega)): central differences over a step short enough to be linear.
  const double h = 1e-4;
  auto seen_after = [&](const Eigen::Vector3d& X_v, double s, Eigen::Vector2d* pixel) {
    const SE2 back = SE2::exp(Eigen::Vector3d(velocity.x() * s, 0.0, velocity.y() * s)).inverse();
    const Eigen::Vector2d moved = back * Eigen::Vector2d(X_v.x(), X_v.y());
    const Eigen::Vector3d X_c = R.transpose() * (Eigen::Vector3d(moved.x(), moved.y(), 0.0) - C);
    if (!(X_c.z() > 0)) return false;
    *pixel = cam.project(X_c);
    return true;
  };
  double fastest = 0.0;
  const int n = 9;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d pixel(i * (cam.width - 1) / double(n - 1), j * (cam.height - 1) / double(n - 1));
      const Eigen::Vector2d ray = cam.unproject(pixel);
      const Eigen::Vector3d d = R * Eigen::Vector3d(ray.x(), ray.y(), 1.0);
      if (!(d.z() < 0)) continue;  // above the horizon: no ground to move
      const Eigen::Vector3d X_v = C - (C.z() / d.z()) * d;
      Eigen::Vector2d a, b;
      if (!seen_after(X_v, -h, &a) || !seen_after(X_v, h, &b)) continue;
      fastest = std::max(fastest, (b - a).norm() / (2 * h));
    }
  return fastest;
}

int exposure_samples(const Options& o, const Trajectory& tr, size_t k) {
  const double E = o.exposure_time;
  if (!(E > 0)) return 1;
  if (k >= tr.t.size()) throw_invalid_argument("exposure_samples: no such frame");
  const double lo = tr.t[k] - E, hi = tr.t[k] + o.readout_time;
  double fastest = 0.0;
  const size_t intervals = tr.velocity.size();
  for (size_t i = 0; i < intervals; ++i) {
    // Interval i spans [t_i, t_i+1]; the last one's velocity also continues after the last frame.
    const bool overlaps = tr.t[i + 1] > lo && tr.t[i] < hi;
    const bool continued = i + 1 == intervals && hi > tr.t[i + 1];
    if (overlaps || continued) fastest = std::max(fastest, image_speed(o, tr.velocity[i]));
  }
  const double n = std::ceil(2.0 * fastest * E);
  return static_cast<int>(std::clamp(n, 1.0, 64.0));
}

cv::Mat render_frame(Renderer& renderer, const Options& o, const Trajectory& tr, size_t k) {
  if (k >= tr.t.size() || tr.t.size() != tr.pose.size())
    throw_invalid_argument("render_frame: no such frame in the trajectory");
  const double readout = o.readout_time, E = o.exposure_time;
  if (readout == 0.0 && E == 0.0)
    return renderer.render_float(tr.pose[k], camera_extrinsics_at(o, tr, tr.t[k]));
  const int height = renderer.rays().height;
  const int n = exposure_samples(o, tr, k);
  cv::Mat sum;
  std::vector<SE2> rows(static_cast<size_t>(height));
  std::vector<Extrinsics> row_extrinsics(static_cast<size_t>(height));
  for (int i = 0; i < n; ++i) {
    // The midpoint of the i-th of n equal parts of [t_row - E, t_row].
    const double offset = E == 0.0 ? 0.0 : -E + (i + 0.5) * E / n;
    cv::Mat image;
    if (readout == 0.0 || height < 2) {
      const double t = tr.t[k] + offset;
      image = renderer.render_float(pose_at(tr, t), camera_extrinsics_at(o, tr, t));
    } else {
      for (int r = 0; r < height; ++r) {
        const double t = tr.t[k] + static_cast<double>(r) / (height - 1) * readout + offset;
        rows[static_cast<size_t>(r)] = pose_at(tr, t);
        row_extrinsics[static_cast<size_t>(r)] = camera_extrinsics_at(o, tr, t);
      }
      image = renderer.render_float_rows(rows, row_extrinsics);
    }
    if (i == 0)
      sum = image;
    else
      sum += image;
  }
  if (n > 1) sum *= 1.0 / n;
  return sum;
}

}  // namespace planarvo::sim
