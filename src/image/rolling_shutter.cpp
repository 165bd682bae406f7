#include "image/rolling_shutter.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/se2.h"
#include "image/pipeline.h"

namespace planarvo {

bool RowWarp::identity() const {
  for (size_t r = 0; r + 9 <= h.size(); r += 9)
    for (size_t i = 0; i < 9; ++i)
      if (h[r + i] != (i % 4 == 0 ? 1.0f : 0.0f)) return false;
  return true;
}

RowWarp identity_row_warp(int height) {
  RowWarp w;
  w.height = std::max(height, 0);
  w.h.assign(static_cast<size_t>(w.height) * 9, 0.0f);
  for (size_t r = 0; r < static_cast<size_t>(w.height); ++r) w.h[9 * r] = w.h[9 * r + 4] = w.h[9 * r + 8] = 1.0f;
  return w;
}

RowWarp rolling_shutter_warp(const CameraModel& camera, const Extrinsics& extrinsics, const Eigen::Vector3d& twist) {
  if (!twist.allFinite()) throw_invalid_argument("rolling_shutter_warp: the twist must be finite");
  RowWarp w = identity_row_warp(camera.height);
  const double readout = camera.rolling_shutter_readout;
  if (!(readout > 0.0) || camera.height < 2 || twist.isZero(0.0)) return w;
  const Eigen::Matrix3d K = camera.K();
  for (int r = 1; r < camera.height; ++r) {
    const double tau = static_cast<double>(r) / (camera.height - 1) * readout;
    // Row r's robot pose in the stamp's robot frame, and the stamp's pixels seen from it.
    Eigen::Matrix3d H = ground_homography(K, extrinsics, SE2::exp(tau * twist).matrix3d());
    H /= H(2, 2);
    for (int i = 0; i < 9; ++i) w.h[9 * static_cast<size_t>(r) + static_cast<size_t>(i)] = static_cast<float>(H(i / 3, i % 3));
  }
  return w;
}

namespace {

// The warp's homography at (fractional) row r, applied to (x, y): the kernel's arithmetic.
void apply_row(const RowWarp& w, float r, float x, float y, float* qx, float* qy) {
  const int i = std::min(static_cast<int>(r), w.height - 2 < 0 ? 0 : w.height - 2);
  const float f = w.height > 1 ? r - static_cast<float>(i) : 0.0f;
  const float* a = w.h.data() + 9 * static_cast<size_t>(i);
  const float* b = w.height > 1 ? a + 9 : a;
  float m[9];
  for (int k = 0; k < 9; ++k) m[k] = a[k] + f * (b[k] - a[k]);
  const float z = m[6] * x + m[7] * y + m[8];
  *qx = (m[0] * x + m[1] * y + m[2]) / z;
  *qy = (m[3] * x + m[4] * y + m[5]) / z;
}

// The map's source coordinate bilinearly interpolated at (x, y): cells clamped to the image,
// extrapolated beyond it.
void map_at(const UndistortMap& map, float x, float y, float* sx, float* sy) {
  // NaN (a degenerate homography) reads cell 0: the result is then not valid anyway.
  const float fx = std::isnan(x) ? 0.0f : std::floor(x), fy = std::isnan(y) ? 0.0f : std::floor(y);
  const int x0 = std::clamp(static_cast<int>(std::clamp(fx, -1.0f, static_cast<float>(map.width))), 0, map.width - 2);
  const int y0 = std::clamp(static_cast<int>(std::clamp(fy, -1.0f, static_cast<float>(map.height))), 0, map.height - 2);
  const float ax = x - static_cast<float>(x0), ay = y - static_cast<float>(y0);
  const size_t i00 = static_cast<size_t>(y0) * static_cast<size_t>(map.width) + static_cast<size_t>(x0);
  const size_t i10 = i00 + static_cast<size_t>(map.width);
  const float* mx = map.map_x.data();
  const float* my = map.map_y.data();
  // a + t (b - a): beyond the image's edge t is large, and this form keeps the rounding of the
  // map's coordinates from being multiplied by it.
  const float tx = mx[i00] + ax * (mx[i00 + 1] - mx[i00]), bx = mx[i10] + ax * (mx[i10 + 1] - mx[i10]);
  const float ty = my[i00] + ax * (my[i00 + 1] - my[i00]), by = my[i10] + ax * (my[i10 + 1] - my[i10]);
  *sx = tx + ay * (bx - tx);
  *sy = ty + ay * (by - ty);
}

}  // namespace

float aitken(float r0, float r1, float r2, float last_row) {
  const float d1 = r1 - r0, d2 = r2 - r1, den = d2 - d1;
  // Only while the steps shrink (a contraction), and not within float noise of converged.
  if (!(std::abs(d2) < 0.9f * std::abs(d1)) || !(std::abs(den) > 1e-4f)) return r2;
  return std::clamp(r2 - d2 * d2 / den, 0.0f, last_row);
}

cv::Mat undistort_rolling_reference(const cv::Mat& gray, const CameraModel& camera, const UndistortMap& map,
                                    const RowWarp& warp) {
  if (gray.type() != CV_8UC1 || gray.cols != camera.width || gray.rows != camera.height)
    throw_invalid_argument("undistort_rolling_reference: the frame must be CV_8UC1 of the camera's size");
  if (map.width != camera.width || map.height != camera.height || map.width < 2 || map.height < 2)
    throw_invalid_argument("undistort_rolling_reference: the map is not the camera's");
  if (warp.height != camera.height || warp.h.size() != static_cast<size_t>(warp.height) * 9)
    throw_invalid_argument("undistort_rolling_reference: the row warp has " + std::to_string(warp.height) +
                           " rows, the camera " + std::to_string(camera.height));
  const PixelRegion roi = camera.region();
  const float min_x = static_cast<float>(roi.x), min_y = static_cast<float>(roi.y);
  const float max_x = static_cast<float>(roi.x + roi.width - 1), max_y = static_cast<float>(roi.y + roi.height - 1);
  const float last_row = static_cast<float>(camera.height - 1);
  const int w = camera.width, h = camera.height;
  cv::Mat out(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v) {
    float* dst = out.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(w) + static_cast<size_t>(u);
      float sx = 0.0f, sy = 0.0f;
      auto at_row = [&](float r) {
        float qx, qy;
        apply_row(warp, r, static_cast<float>(u), static_cast<float>(v), &qx, &qy);
        map_at(map, qx, qy, &sx, &sy);
        return std::clamp(sy, 0.0f, last_row);  // NaN-free: the map and the warp are finite
      };
      const float r0 = std::clamp(map.map_y[i], 0.0f, last_row);
      const float r1 = at_row(r0);
      const float r2 = at_row(r1);
      at_row(aitken(r0, r1, r2, last_row));
      if (!(sx >= min_x && sx <= max_x && sy >= min_y && sy <= max_y)) {
        dst[u] = kInvalidIntensity;
        continue;
      }
      // remap_bilinear's sampling.
      const int x0 = static_cast<int>(sx), y0 = static_cast<int>(sy);
      const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
      const float ax = sx - static_cast<float>(x0), ay = sy - static_cast<float>(y0);
      const uint8_t* top_row = gray.ptr<uint8_t>(y0);
      const uint8_t* bottom_row = gray.ptr<uint8_t>(y1);
      const float top = (1.0f - ax) * static_cast<float>(top_row[x0]) + ax * static_cast<float>(top_row[x1]);
      const float bottom = (1.0f - ax) * static_cast<float>(bottom_row[x0]) + ax * static_cast<float>(bottom_row[x1]);
      dst[u] = (1.0f - ay) * top + ay * bottom;
    }
  }
  return out;
}

}  // namespace planarvo
