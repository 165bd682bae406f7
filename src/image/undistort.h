// The undistortion map: for every pixel of the undistorted image, where to sample the distorted
// camera image, with the undistorted image's camera matrix equal to K (what
// cv::initUndistortRectifyMap(K, D, I, K, size, CV_32FC1) computes). Computed once per camera,
// in double; the OpenCL undistortion kernel samples it, and remap_bilinear is its C++ reference.
#pragma once
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera.h"

namespace planarvo {

struct UndistortMap {
  int width = 0, height = 0;
  // Row-major, width * height each: the source (distorted) pixel coordinate of output pixel
  // (u, v) at index v * width + u.
  std::vector<float> map_x, map_y;
  // 1 where the source lies inside the camera's region of interest (the whole image by
  // default) so that bilinear sampling has all four neighbours there: x <= map_x <= x + width - 1
  // and y <= map_y <= y + height - 1 of CameraModel::region(). 0 elsewhere.
  std::vector<uint8_t> valid;

  size_t valid_count() const;
};

// Throws InvalidArgument when the camera does not validate.
UndistortMap compute_undistort_map(const CameraModel& camera);

// Bilinear sampling of src (CV_8UC1 or CV_32FC1, the map's size) at the map's coordinates: a
// CV_32FC1 image of the map's size, 0 where the map is not valid. The weights are computed in
// float from the float map, as the OpenCL kernel does. Throws InvalidArgument on a wrong type or
// size.
cv::Mat remap_bilinear(const cv::Mat& src, const UndistortMap& map);

}  // namespace planarvo
