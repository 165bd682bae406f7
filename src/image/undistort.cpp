#include "image/undistort.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace planarvo {

size_t UndistortMap::valid_count() const {
  return static_cast<size_t>(std::count(valid.begin(), valid.end(), uint8_t{1}));
}

UndistortMap compute_undistort_map(const CameraModel& camera) {
  try {
    camera.validate("compute_undistort_map");
  } catch (const Error& e) {
    throw_invalid_argument(e.what());
  }
  UndistortMap m;
  m.width = camera.width;
  m.height = camera.height;
  const size_t n = static_cast<size_t>(m.width) * static_cast<size_t>(m.height);
  m.map_x.resize(n);
  m.map_y.resize(n);
  m.valid.resize(n);
  // The bilinear footprint must lie inside the region of interest (the whole image by default).
  const PixelRegion roi = camera.region();
  const float min_x = static_cast<float>(roi.x), min_y = static_cast<float>(roi.y);
  const float max_x = static_cast<float>(roi.x + roi.width - 1), max_y = static_cast<float>(roi.y + roi.height - 1);
  for (int v = 0; v < m.height; ++v) {
    const double yn = (v - camera.cy) / camera.fy;
    for (int u = 0; u < m.width; ++u) {
      // Output pixel -> undistorted normalised ray (new camera matrix K) -> distorted pixel.
      const Eigen::Vector2d d = camera.distort(Eigen::Vector2d((u - camera.cx) / camera.fx, yn));
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(m.width) + static_cast<size_t>(u);
      const float sx = static_cast<float>(camera.fx * d.x() + camera.cx);
      const float sy = static_cast<float>(camera.fy * d.y() + camera.cy);
      m.map_x[i] = sx;
      m.map_y[i] = sy;
      // Judged on the float values the sampler will see (false for NaN).
      m.valid[i] = (sx >= min_x && sx <= max_x && sy >= min_y && sy <= max_y) ? 1 : 0;
    }
  }
  return m;
}

namespace {

template <typename T>
void remap_rows(const cv::Mat& src, const UndistortMap& map, cv::Mat& dst) {
  const int w = map.width, h = map.height;
  for (int v = 0; v < h; ++v) {
    float* out = dst.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(w) + static_cast<size_t>(u);
      if (!map.valid[i]) {
        out[u] = 0.0f;
        continue;
      }
      const float sx = map.map_x[i], sy = map.map_y[i];
      const int x0 = static_cast<int>(std::floor(sx)), y0 = static_cast<int>(std::floor(sy));
      // On the last row/column the far neighbour has weight 0; clamp it to stay inside.
      const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
      const float ax = sx - static_cast<float>(x0), ay = sy - static_cast<float>(y0);
      const T* r0 = src.ptr<T>(y0);
      const T* r1 = src.ptr<T>(y1);
      const float top = (1.0f - ax) * static_cast<float>(r0[x0]) + ax * static_cast<float>(r0[x1]);
      const float bottom = (1.0f - ax) * static_cast<float>(r1[x0]) + ax * static_cast<float>(r1[x1]);
      out[u] = (1.0f - ay) * top + ay * bottom;
    }
  }
}

}  // namespace

cv::Mat remap_bilinear(const cv::Mat& src, const UndistortMap& map) {
  if (src.type() != CV_8UC1 && src.type() != CV_32FC1)
    throw_invalid_argument("remap_bilinear: the source must be CV_8UC1 or CV_32FC1");
  if (src.cols != map.width || src.rows != map.height)
    throw_invalid_argument("remap_bilinear: the source is " + std::to_string(src.cols) + "x" +
                           std::to_string(src.rows) + ", the map " + std::to_string(map.width) +
                           "x" + std::to_string(map.height));
  const size_t n = static_cast<size_t>(map.width) * static_cast<size_t>(map.height);
  if (map.map_x.size() != n || map.map_y.size() != n || map.valid.size() != n)
    throw_invalid_argument("remap_bilinear: the map's arrays do not match its size");
  cv::Mat dst(map.height, map.width, CV_32FC1);
  if (src.type() == CV_8UC1)
    remap_rows<uint8_t>(src, map, dst);
  else
    remap_rows<float>(src, map, dst);
  return dst;
}

}  // namespace planarvo
