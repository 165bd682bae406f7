// Host-side pyramids for the tracker's tests and benchmark, following the pyramid contract of
// src/image/pyramid.h (and the image pipeline's definition of each stage): undistortion by
// bilinear remap, the centre-aligned Gaussian step [1 5 10 10 5 1] / 32 (the 5-tap [1 4 6 4 1]
// / 16 sampled between two pixels), central-difference gradients, float4 upload. Independent
// of the OpenCL image pipeline so the tracker can be tested on its own.
#pragma once
#include <algorithm>
#include <vector>

#include <opencv2/core.hpp>

#include "image/camera.h"
#include "image/pyramid.h"
#include "image/undistort.h"
#include "ocl/runtime.h"

namespace planarvo::test {

inline constexpr float kTestInvalid = -1.0f;

// Undistorted intensity image (CV_32FC1), kTestInvalid where the map has no source.
inline cv::Mat test_undistort(const cv::Mat& image, const UndistortMap& map) {
  cv::Mat out = remap_bilinear(image, map);
  for (int y = 0; y < out.rows; ++y)
    for (int x = 0; x < out.cols; ++x)
      if (!map.valid[static_cast<size_t>(y) * out.cols + x]) out.at<float>(y, x) = kTestInvalid;
  return out;
}

// One Gaussian pyramid step of an intensity image, invalid taps making the output invalid.
inline cv::Mat test_downsample(const cv::Mat& in) {
  static const float w[6] = {1, 5, 10, 10, 5, 1};
  const int W = (in.cols + 1) / 2, H = (in.rows + 1) / 2;
  cv::Mat out(H, W, CV_32FC1);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      float sum = 0.0f;
      bool ok = true;
      for (int j = 0; j < 6; ++j) {
        const int y = std::clamp(2 * v - 2 + j, 0, in.rows - 1);
        float rs = 0.0f;
        for (int i = 0; i < 6; ++i) {
          const int x = std::clamp(2 * u - 2 + i, 0, in.cols - 1);
          const float p = in.at<float>(y, x);
          ok = ok && p >= 0.0f;
          rs += w[i] * p;
        }
        sum += w[j] * rs;
      }
      out.at<float>(v, u) = ok ? sum / 1024.0f : kTestInvalid;
    }
  return out;
}

// The float4 level: (I, dI/du, dI/dv, 1), zeros where the pixel or a neighbour is invalid.
inline cv::Mat test_gradient(const cv::Mat& in) {
  cv::Mat out(in.rows, in.cols, CV_32FC4, cv::Scalar::all(0));
  for (int y = 1; y + 1 < in.rows; ++y)
    for (int x = 1; x + 1 < in.cols; ++x) {
      const float c = in.at<float>(y, x), l = in.at<float>(y, x - 1), r = in.at<float>(y, x + 1);
      const float t = in.at<float>(y - 1, x), b = in.at<float>(y + 1, x);
      if (c < 0 || l < 0 || r < 0 || t < 0 || b < 0) continue;
      out.at<cv::Vec4f>(y, x) = cv::Vec4f(c, (r - l) * 0.5f, (b - t) * 0.5f, 1.0f);
    }
  return out;
}

// Every level of the pyramid of a camera image (CV_8UC1 or CV_32FC1, distorted): undistorted
// with `map` when given, else taken as already undistorted.
inline std::vector<cv::Mat> test_pyramid(const cv::Mat& image, const UndistortMap* map, int levels) {
  cv::Mat level;
  if (map) {
    level = test_undistort(image, *map);
  } else {
    image.convertTo(level, CV_32FC1);
  }
  std::vector<cv::Mat> out;
  for (int l = 0; l < levels; ++l) {
    if (l > 0) level = test_downsample(level);
    out.push_back(test_gradient(level));
  }
  return out;
}

inline Pyramid test_upload(ocl::Runtime& rt, const std::vector<cv::Mat>& levels) {
  Pyramid p;
  for (const cv::Mat& m : levels) {
    PyramidLevel l;
    l.width = m.cols;
    l.height = m.rows;
    cv::Mat c = m.isContinuous() ? m : m.clone();
    l.data = cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, c.total() * 16, c.data);
    p.levels.push_back(l);
  }
  return p;
}

}  // namespace planarvo::test
