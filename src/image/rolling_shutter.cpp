#include "image/rolling_shutter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/se2.h"
#include "image/pipeline.h"

namespace planarvo {

namespace {

// Ground homographies H(tau) at kSamples row times (CameraModel::row_time: the read times less
// half the exposure) evenly spaced over the readout, interpolated
// between them by Catmull-Rom splines (smooth across the samples, so that the field the grid
// interpolates has no kinks; under 1e-5 px from the exact H over 30 ms at 1.5 m/s and 1.2 rad/s)
// and extrapolated linearly beyond the first and last rows.
class RowHomographies {
 public:
  static constexpr int kSamples = 33;
  RowHomographies(const CameraModel& camera, const Extrinsics& e, const Eigen::Vector3d& twist)
      : rows_(camera.height) {
    const Eigen::Matrix3d K = camera.K();
    for (int k = 0; k < kSamples; ++k) {
      const double tau = camera.row_time(static_cast<double>(k) / (kSamples - 1) * (camera.height - 1));
      H_[k] = ground_homography(K, e, SE2::exp(tau * twist).matrix3d());
      H_[k] /= H_[k](2, 2);
    }
    tabulate();
  }
  // H at sensor row r (Catmull-Rom between the samples).
  Eigen::Matrix3d spline(double r) const {
    const double x = r / std::max(rows_ - 1, 1) * (kSamples - 1);
    if (x <= 0.0) return H_[0] + x * (H_[1] - H_[0]);
    if (x >= kSamples - 1) return H_[kSamples - 1] + (x - (kSamples - 1)) * (H_[kSamples - 1] - H_[kSamples - 2]);
    const int i = std::min(static_cast<int>(x), kSamples - 2);
    const double t = x - i, t2 = t * t, t3 = t2 * t;
    // The neighbours beyond the ends reflected linearly.
    const Eigen::Matrix3d p0 = i > 0 ? H_[i - 1] : Eigen::Matrix3d(2.0 * H_[0] - H_[1]);
    const Eigen::Matrix3d p3 = i + 2 < kSamples ? H_[i + 2] : Eigen::Matrix3d(2.0 * H_[kSamples - 1] - H_[kSamples - 2]);
    const Eigen::Matrix3d& p1 = H_[i];
    const Eigen::Matrix3d& p2 = H_[i + 1];
    return 0.5 * ((2.0 * p1) + (-p0 + p2) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2 +
                  (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t3);
  }

  // The spline tabulated at every sensor row, for at(): linear between rows (their spacing makes
  // that exact to 1e-8 px), which is what the solver evaluates thousands of times per frame.
  void tabulate() {
    table_.resize(9 * static_cast<size_t>(rows_));
    for (int r = 0; r < rows_; ++r) {
      const Eigen::Matrix3d m = spline(r);
      for (int k = 0; k < 9; ++k) table_[9 * static_cast<size_t>(r) + static_cast<size_t>(k)] = m(k / 3, k % 3);
    }
  }

  // H p (homogeneous, not divided) at sensor row r: the table, extrapolated linearly beyond it.
  Eigen::Vector3d apply(double r, const Eigen::Vector2d& p) const {
    const int i = std::clamp(static_cast<int>(std::floor(r)), 0, std::max(rows_ - 2, 0));
    const double f = rows_ > 1 ? r - i : 0.0;
    const double* a = table_.data() + 9 * static_cast<size_t>(i);
    const double* b = rows_ > 1 ? a + 9 : a;
    double m[9];
    for (int k = 0; k < 9; ++k) m[k] = a[k] + f * (b[k] - a[k]);
    return {m[0] * p.x() + m[1] * p.y() + m[2], m[3] * p.x() + m[4] * p.y() + m[5], m[6] * p.x() + m[7] * p.y() + m[8]};
  }

 private:
  int rows_;
  Eigen::Matrix3d H_[kSamples];
  std::vector<double> table_;
};

Eigen::Vector2d distorted_pixel(const CameraModel& c, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = c.distort(Eigen::Vector2d((p.x() - c.cx) / c.fx, (p.y() - c.cy) / c.fy));
  return {c.fx * d.x() + c.cx, c.fy * d.y() + c.cy};
}

// The fixed point r = row(distort(H_r p)) (rolling_shutter.h): plain steps, with Aitken's
// extrapolation every two. Not clamped to the sensor's rows (a source outside the sensor has no
// sample anyway, and the grid's nodes there keep the field smooth for the pixels inside); held
// within a frame's height beyond them so that nothing diverges.
// start: a first row (a neighbouring node's solution), or NaN for the global shutter's row.
// The source s = distort(q) and q = H_r p, the undistorted pixel of a global shutter that reads s.
struct Source {
  Eigen::Vector2d s, q;
};
Source solve_source(const CameraModel& c, const RowHomographies& H, const Eigen::Vector2d& p,
                    double start = std::numeric_limits<double>::quiet_NaN()) {
  const double first = -(c.height - 1.0), last = 2.0 * (c.height - 1);
  auto source = [&](double r) {
    const Eigen::Vector3d h = H.apply(r, p);
    const Eigen::Vector2d q = h.head<2>() / h.z();
    return Source{distorted_pixel(c, q), q};
  };
  auto row = [&](const Source& s) { return std::isfinite(s.s.y()) ? std::clamp(s.s.y(), first, last) : 0.0; };
  double r = std::isfinite(start) ? std::clamp(start, first, last) : row(Source{distorted_pixel(c, p), p});
  for (int it = 0; it < 8; ++it) {
    // A start this close (a neighbour's row, extrapolated) is taken as it is: the source found
    // from it is within the contraction times 1e-4 rows of the fixed point's.
    const Source s = source(r);
    const double r1 = row(s);
    if (std::abs(r1 - r) < 1e-4) return s;
    const double r2 = row(source(r1));
    const double d1 = r1 - r, d2 = r2 - r1, den = d2 - d1;
    const double next = std::abs(d2) < 0.9 * std::abs(d1) && std::abs(den) > 1e-12 ? std::clamp(r2 - d2 * d2 / den, first, last) : r2;
    // Aitken's error is quadratic in the step's for a function this nearly linear: a step under
    // 0.01 rows leaves under 1e-5.
    const bool done = std::abs(d2) < 1e-2;
    r = next;
    if (done) break;
  }
  return source(r);
}

}  // namespace

bool RowWarp::identity() const {
  auto zero = [](float d) { return d == 0.0f; };
  return std::all_of(delta.begin(), delta.end(), zero) && std::all_of(light.begin(), light.end(), zero);
}

Eigen::Vector2f row_warp_at(const RowWarp& warp, const std::vector<float>& field, int u, int v) {
  const float inv_step = 1.0f / static_cast<float>(warp.step);
  const float gy = static_cast<float>(v) * inv_step;
  const int j = std::min(static_cast<int>(gy), warp.nodes_y - 2);
  const float ay = gy - static_cast<float>(j);
  const float gx = static_cast<float>(u) * inv_step;
  const int i = std::min(static_cast<int>(gx), warp.nodes_x - 2);
  const float ax = gx - static_cast<float>(i);
  const size_t n00 = 2 * (static_cast<size_t>(j) * static_cast<size_t>(warp.nodes_x) + static_cast<size_t>(i));
  const size_t n10 = n00 + 2 * static_cast<size_t>(warp.nodes_x);
  const float* g = field.data();
  Eigen::Vector2f d;
  for (int c = 0; c < 2; ++c) {  // between the node rows first, as the kernels
    const float left = g[n00 + c] + ay * (g[n10 + c] - g[n00 + c]);
    const float right = g[n00 + 2 + c] + ay * (g[n10 + 2 + c] - g[n00 + 2 + c]);
    d[c] = left + ax * (right - left);
  }
  return d;
}

RowWarp identity_row_warp(int width, int height, int step) {
  if (width < 1 || height < 1 || step < 8)
    throw_invalid_argument("identity_row_warp: the size must be positive and the step at least 8");
  RowWarp w;
  w.width = width;
  w.height = height;
  w.step = step;
  w.nodes_x = (width - 1) / step + 2;
  w.nodes_y = (height - 1) / step + 2;
  w.delta.assign(2 * static_cast<size_t>(w.nodes_x) * static_cast<size_t>(w.nodes_y), 0.0f);
  w.light = w.delta;
  return w;
}

Eigen::Vector2d rolling_shutter_source(const CameraModel& camera, const Extrinsics& extrinsics,
                                       const Eigen::Vector3d& twist, double u, double v) {
  const RowHomographies H(camera, extrinsics, twist);
  return solve_source(camera, H, Eigen::Vector2d(u, v)).s;
}

RowWarp rolling_shutter_warp(const CameraModel& camera, const Extrinsics& extrinsics, const Eigen::Vector3d& twist,
                             int step) {
  if (!twist.allFinite()) throw_invalid_argument("rolling_shutter_warp: the twist must be finite");
  RowWarp w = identity_row_warp(camera.width, camera.height, step);
  if (!camera.timed_rows() || twist.isZero(0.0)) return w;
  const RowHomographies H(camera, extrinsics, twist);
  // Solved exactly at every second node column and row and at the outermost ones (those without
  // three nodes on both sides); the rest filled in by the cubic through the four nearest solved
  // nodes of its row or column, whose error is the field's fourth derivative over 32 px: within
  // 0.0034 px of the exact nodes at a 75 px shear (RollingShutter.GridMatchesThePerPixelSolution),
  // a tenth of the bilinear interpolation's between nodes, for about a third of the solves.
  auto solved = [](int i, int n) { return i % 2 == 0 || i < 3 || i + 3 > n - 1; };
  const size_t nx = static_cast<size_t>(w.nodes_x);
  auto at = [&](int i, int j) { return 2 * (static_cast<size_t>(j) * nx + static_cast<size_t>(i)); };
  // Each solved node starts from its two left neighbours' rows extrapolated (the first two of a
  // row from the node above): mostly one evaluation, else one Aitken step.
  double above = std::numeric_limits<double>::quiet_NaN();
  for (int j = 0; j < w.nodes_y; ++j) {
    if (!solved(j, w.nodes_y)) continue;
    double left = above, before_left = std::numeric_limits<double>::quiet_NaN();
    int left_i = -1, before_i = -1;
    for (int i = 0; i < w.nodes_x; ++i) {
      if (!solved(i, w.nodes_x)) continue;
      const Eigen::Vector2d p(i * step, j * step);
      // The extrapolation by the solved nodes' own spacing (1 or 2 columns).
      const double start =
          std::isfinite(before_left) ? left + (left - before_left) * (i - left_i) / (left_i - before_i) : left;
      const Source s = solve_source(camera, H, p, start);
      before_left = left_i >= 0 ? left : std::numeric_limits<double>::quiet_NaN();
      before_i = left_i;
      left = s.s.y();
      left_i = i;
      if (i == 0) above = s.s.y();
      const Eigen::Vector2d d = s.s - distorted_pixel(camera, p), l = s.q - p;
      const bool finite = d.allFinite() && l.allFinite();
      w.delta[at(i, j)] = finite ? static_cast<float>(d.x()) : 0.0f;
      w.delta[at(i, j) + 1] = finite ? static_cast<float>(d.y()) : 0.0f;
      w.light[at(i, j)] = finite ? static_cast<float>(l.x()) : 0.0f;
      w.light[at(i, j) + 1] = finite ? static_cast<float>(l.y()) : 0.0f;
    }
  }
  // The cubic through nodes -3, -1, +1, +3 (in the fine grid's steps) at 0: (-1, 9, 9, -1) / 16,
  // along (di, dj). Every node not solved has them solved (odd, with three nodes on both sides):
  // the solved rows first, along x; then the other rows, along y, from the rows now complete.
  auto fill = [&](int i, int j, int di, int dj) {
    for (std::vector<float>* field : {&w.delta, &w.light})
      for (size_t c = 0; c < 2; ++c) {
        auto g = [&](int k) { return (*field)[at(i + k * di, j + k * dj) + c]; };
        (*field)[at(i, j) + c] = (9.0f * (g(-1) + g(1)) - (g(-3) + g(3))) * (1.0f / 16.0f);
      }
  };
  for (int j = 0; j < w.nodes_y; ++j)
    for (int i = 0; i < w.nodes_x; ++i)
      if (solved(j, w.nodes_y) && !solved(i, w.nodes_x)) fill(i, j, 1, 0);
  for (int j = 0; j < w.nodes_y; ++j)
    for (int i = 0; i < w.nodes_x; ++i)
      if (!solved(j, w.nodes_y)) fill(i, j, 0, 1);
  return w;
}

cv::Mat undistort_rolling_reference(const cv::Mat& gray, const CameraModel& camera, const UndistortMap& map,
                                    const RowWarp& warp) {
  if (gray.type() != CV_8UC1 || gray.cols != camera.width || gray.rows != camera.height)
    throw_invalid_argument("undistort_rolling_reference: the frame must be CV_8UC1 of the camera's size");
  if (map.width != camera.width || map.height != camera.height)
    throw_invalid_argument("undistort_rolling_reference: the map is not the camera's");
  if (warp.width != camera.width || warp.height != camera.height || warp.nodes_x < 2 || warp.nodes_y < 2 ||
      warp.delta.size() != 2 * static_cast<size_t>(warp.nodes_x) * static_cast<size_t>(warp.nodes_y))
    throw_invalid_argument("undistort_rolling_reference: the row warp is not for this camera's size");
  const PixelRegion roi = camera.region();
  const float min_x = static_cast<float>(roi.x), min_y = static_cast<float>(roi.y);
  const float max_x = static_cast<float>(roi.x + roi.width - 1), max_y = static_cast<float>(roi.y + roi.height - 1);
  const int w = camera.width, h = camera.height;
  cv::Mat out(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v) {
    float* dst = out.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2f d = row_warp_at(warp, warp.delta, u, v);
      const size_t p = static_cast<size_t>(v) * static_cast<size_t>(w) + static_cast<size_t>(u);
      const float sx = map.map_x[p] + d[0], sy = map.map_y[p] + d[1];
      if (!(sx >= min_x && sx <= max_x && sy >= min_y && sy <= max_y)) {
        dst[u] = kInvalidIntensity;
        continue;
      }
      // remap_bilinear's sampling.
      const int x0 = static_cast<int>(sx), y0 = static_cast<int>(sy);
      const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
      const float bx = sx - static_cast<float>(x0), by = sy - static_cast<float>(y0);
      const uint8_t* top_row = gray.ptr<uint8_t>(y0);
      const uint8_t* bottom_row = gray.ptr<uint8_t>(y1);
      const float top = (1.0f - bx) * static_cast<float>(top_row[x0]) + bx * static_cast<float>(top_row[x1]);
      const float bottom = (1.0f - bx) * static_cast<float>(bottom_row[x0]) + bx * static_cast<float>(bottom_row[x1]);
      dst[u] = (1.0f - by) * top + by * bottom;
    }
  }
  return out;
}

}  // namespace planarvo
