// Pyramids for the tracker's tests and benchmark from the image pipeline's plain C++ reference
// (image/pipeline.h), so that noise-free float renders can be tracked without 8-bit rounding:
// an 8-bit frame goes through the whole reference (undistortion included); a float image is
// taken as already undistorted and only blurred, decimated and differentiated.
#pragma once
#include <vector>

#include <opencv2/core.hpp>

#include "image/pipeline.h"
#include "image/pyramid.h"
#include "image/undistort.h"
#include "ocl/runtime.h"

namespace planarvo::test {

inline std::vector<cv::Mat> test_pyramid(const cv::Mat& image, const UndistortMap* map, int levels) {
  if (map && image.type() == CV_8UC1) return pipeline_reference(image, *map, levels);
  cv::Mat level;
  if (map) {
    level = remap_bilinear(image, *map);
    for (int y = 0; y < level.rows; ++y)
      for (int x = 0; x < level.cols; ++x)
        if (!map->valid[static_cast<size_t>(y) * level.cols + x]) level.at<float>(y, x) = kInvalidIntensity;
  } else {
    image.convertTo(level, CV_32FC1);
  }
  std::vector<cv::Mat> out;
  for (int l = 0; l < levels; ++l) {
    if (l > 0) level = downsample_reference(level);
    out.push_back(gradient_reference(level));
  }
  return out;
}

inline Pyramid test_upload(ocl::Runtime& rt, const std::vector<cv::Mat>& levels) {
  return upload_pyramid(rt, levels);
}

}  // namespace planarvo::test
