// The per-frame image pyramid on the device: what the image pipeline (undistortion, Gaussian
// pyramid, gradients) produces and the tracker consumes.
//
// Layout, one buffer per level: float4 per pixel, row-major, row stride == width:
//   .x  intensity, grey levels 0..255 (undistorted: the pinhole camera K, no distortion)
//   .y  dI/du, .z dI/dv: central differences at this level, in grey levels per pixel
//   .w  1.0f where the pixel and every value it was computed from are valid, else 0.0f (no
//       source pixel after undistortion, a Gaussian tap on an invalid pixel, a gradient
//       neighbour invalid or outside the image); .x/.y/.z are 0 where .w is 0.
// Pixel centres across levels: level-l pixel (u, v) is level-0 (2^l (u + 0.5) - 0.5, ...), so
// the camera matrix of level l is fx/2^l, fy/2^l, (cx + 0.5)/2^l - 0.5, (cy + 0.5)/2^l - 0.5
// (level_camera_matrix). Level l is ceil(w / 2^l) x ceil(h / 2^l) pixels (level_size).
#pragma once
#include <vector>

#include <CL/opencl.hpp>
#include <Eigen/Core>

namespace planarvo {

struct PyramidLevel {
  int width = 0, height = 0;
  cl::Buffer data;  // width * height float4
};

struct Pyramid {
  std::vector<PyramidLevel> levels;  // levels[0] is full resolution
  int num_levels() const { return static_cast<int>(levels.size()); }
};

inline Eigen::Matrix3d level_camera_matrix(const Eigen::Matrix3d& K, int level) {
  const double s = 1.0 / static_cast<double>(1 << level);
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = K(0, 0) * s;
  k(1, 1) = K(1, 1) * s;
  k(0, 2) = (K(0, 2) + 0.5) * s - 0.5;
  k(1, 2) = (K(1, 2) + 0.5) * s - 0.5;
  return k;
}

inline int level_size(int full, int level) { return (full + (1 << level) - 1) >> level; }

}  // namespace planarvo
