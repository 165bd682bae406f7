// The plain C++ reference of the image pipeline's kernels (kernels/image/undistort.cl,
// kernels/image/pyramid.cl), stage by stage, in the kernels' float operations and order, so that the
// kernel tests can hold them to a few float roundings.
#include <algorithm>
#include <string>

#include "core/error.h"
#include "image/pipeline.h"

namespace planarvo {
namespace {

void check_intensity(const cv::Mat& level, const char* what) {
  if (level.type() != CV_32FC1 || level.empty())
    throw_invalid_argument(std::string(what) + ": the level must be a non-empty CV_32FC1 image");
}

}  // namespace

cv::Mat undistort_reference(const cv::Mat& gray, const UndistortMap& map) {
  if (gray.type() != CV_8UC1)
    throw_invalid_argument("undistort_reference: the frame must be CV_8UC1");
  cv::Mat out = remap_bilinear(gray, map);
  for (int v = 0; v < out.rows; ++v) {
    float* row = out.ptr<float>(v);
    const uint8_t* valid = map.valid.data() + static_cast<size_t>(v) * static_cast<size_t>(map.width);
    for (int u = 0; u < out.cols; ++u)
      if (!valid[u]) row[u] = kInvalidIntensity;
  }
  return out;
}

cv::Mat smooth_reference(const cv::Mat& level) {
  check_intensity(level, "smooth_reference");
  const int w = level.cols, h = level.rows;
  cv::Mat out(h, w, CV_32FC1);
  for (int v = 0; v < h; ++v) {
    const float* rows[3];
    for (int i = 0; i < 3; ++i) rows[i] = level.ptr<float>(std::clamp(v - 1 + i, 0, h - 1));
    float* dst = out.ptr<float>(v);
    for (int u = 0; u < w; ++u) {
      const int c0 = std::max(u - 1, 0), c2 = std::min(u + 1, w - 1);
      float s[3];
      bool valid = true;
      for (int i = 0; i < 3; ++i) {
        const float a = rows[i][c0], b = rows[i][u], c = rows[i][c2];
        valid = valid && a >= 0.0f && b >= 0.0f && c >= 0.0f;
        s[i] = (a + c) + 2.0f * b;
      }
      dst[u] = valid ? ((s[0] + s[2]) + 2.0f * s[1]) * (1.0f / 16.0f) : kInvalidIntensity;
    }
  }
  return out;
}

cv::Mat downsample_reference(const cv::Mat& level) {
  check_intensity(level, "downsample_reference");
  const int sw = level.cols, sh = level.rows;
  const int dw = level_size(sw, 1), dh = level_size(sh, 1);
  cv::Mat out(dh, dw, CV_32FC1);
  for (int v = 0; v < dh; ++v) {
    const float* rows[6];
    for (int i = 0; i < 6; ++i) rows[i] = level.ptr<float>(std::clamp(2 * v - 2 + i, 0, sh - 1));
    float* dst = out.ptr<float>(v);
    for (int u = 0; u < dw; ++u) {
      int c[6];
      for (int i = 0; i < 6; ++i) c[i] = std::clamp(2 * u - 2 + i, 0, sw - 1);
      float h[6];
      bool valid = true;
      for (int i = 0; i < 6; ++i) {
        const float* r = rows[i];
        const float a0 = r[c[0]], a1 = r[c[1]], a2 = r[c[2]], a3 = r[c[3]], a4 = r[c[4]], a5 = r[c[5]];
        valid = valid && a0 >= 0.0f && a1 >= 0.0f && a2 >= 0.0f && a3 >= 0.0f && a4 >= 0.0f &&
                a5 >= 0.0f;
        h[i] = (a0 + a5) + 5.0f * (a1 + a4) + 10.0f * (a2 + a3);
      }
      const float s = (h[0] + h[5]) + 5.0f * (h[1] + h[4]) + 10.0f * (h[2] + h[3]);
      dst[u] = valid ? s * (1.0f / 1024.0f) : kInvalidIntensity;
    }
  }
  return out;
}

cv::Mat gradient_reference(const cv::Mat& level) {
  check_intensity(level, "gradient_reference");
  const int w = level.cols, h = level.rows;
  cv::Mat out(h, w, CV_32FC4);
  for (int v = 0; v < h; ++v) {
    const float* row = level.ptr<float>(v);
    const float* up = v > 0 ? level.ptr<float>(v - 1) : nullptr;
    const float* down = v + 1 < h ? level.ptr<float>(v + 1) : nullptr;
    cv::Vec4f* dst = out.ptr<cv::Vec4f>(v);
    for (int u = 0; u < w; ++u) {
      const float c = row[u];
      const float l = u > 0 ? row[u - 1] : kInvalidIntensity;
      const float r = u + 1 < w ? row[u + 1] : kInvalidIntensity;
      const float t = up ? up[u] : kInvalidIntensity;
      const float b = down ? down[u] : kInvalidIntensity;
      const bool valid = c >= 0.0f && l >= 0.0f && r >= 0.0f && t >= 0.0f && b >= 0.0f;
      dst[u] = valid ? cv::Vec4f(c, (r - l) * 0.5f, (b - t) * 0.5f, 1.0f) : cv::Vec4f(0, 0, 0, 0);
    }
  }
  return out;
}

std::vector<cv::Mat> pipeline_reference(const cv::Mat& gray, const UndistortMap& map, int levels,
                                        bool prefilter) {
  if (levels < 1 || levels > kMaxPyramidLevels)
    throw_invalid_argument("pipeline_reference: levels must be 1.." +
                           std::to_string(kMaxPyramidLevels) + ", not " + std::to_string(levels));
  std::vector<cv::Mat> out;
  cv::Mat intensity = undistort_reference(gray, map);
  if (prefilter) intensity = smooth_reference(intensity);
  for (int l = 0; l < levels; ++l) {
    if (l > 0) intensity = downsample_reference(intensity);
    out.push_back(gradient_reference(intensity));
  }
  return out;
}

}  // namespace planarvo
