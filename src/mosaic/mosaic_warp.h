// The mosaic's per-frame warp (kernels/mosaic/mosaic.cl): its parameters, its plain C++ reference, and
// the host side that runs the kernel. One frame's window of the mosaic grid is mapped through the
// plane-induced homography (the paper's eq. 3, here from ground-grid pixels to the camera) and
// the camera's distortion to the frame's pixels, and sampled with a feathering weight
// (src/mosaic/README.md).
#pragma once
#include <array>
#include <memory>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "core/extrinsics.h"
#include "core/se2.h"
#include "kernels/mosaic/mosaic_project.h"
#include "ocl/runtime.h"

namespace planarvo::mosaic {

// The mosaic's pixel grid in the trajectory's frame, as ROS map_server places an image: pixel
// (col, row) covers x in origin.x + [col, col + 1) * resolution and y in
// origin.y + [height - 1 - row, height - row) * resolution (row 0 at the top, +y up).
struct MosaicGrid {
  double resolution = 0.001;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // lower-left corner of the lower-left pixel
  int width = 0, height = 0;
  // The ground point at a (fractional) pixel position; the pixel centre is (col + 0.5, row + 0.5).
  Eigen::Vector2d ground(double col, double row) const {
    return {origin.x() + col * resolution, origin.y() + (height - row) * resolution};
  }
};

// A rectangle of mosaic pixels: columns x .. x + width - 1, rows y .. y + height - 1.
struct Window {
  int x = 0, y = 0, width = 0, height = 0;
  bool empty() const { return width <= 0 || height <= 0; }
};

// The parameter block's layout: kernels/mosaic/mosaic_project.h's, which the kernel reads by.
enum MosaicWarpParam {
  kParamH = PV_MOSAIC_H,                      // 9: window pixel (col + 0.5, row + 0.5, 1) -> camera-frame ground point
  kParamIntrinsics = PV_MOSAIC_INTRINSICS,    // fx fy cx cy
  kParamDistortion = PV_MOSAIC_DISTORTION,    // k1 k2 p1 p2 k3
  kParamMaxRadius2 = PV_MOSAIC_MAX_RADIUS2,   // the distortion model's domain: squared undistorted radius
  kParamRegion = PV_MOSAIC_REGION,            // first column, first row, last column, last row (inclusive)
  kParamInvFeather = PV_MOSAIC_INV_FEATHER,   // 1 / the feathering ramp in frame pixels
  kParamFoot = PV_MOSAIC_FOOT,                // 2: the camera's foot point in window pixels
  kParamRange2 = PV_MOSAIC_RANGE2,            // squared range limit in mosaic pixels
  // A rolling shutter (docs/conventions.md: row r is read at stamp + r / (rows - 1) * readout):
  // the homographies of the robot's poses when the middle row and the last row were read (kParamH
  // is the first row's), and 1 / (rows - 1) of the frame; 0 there for a global shutter.
  kParamHMiddle = PV_MOSAIC_H_MIDDLE,         // 9
  kParamHLast = PV_MOSAIC_H_LAST,             // 9
  kParamInvRows = PV_MOSAIC_INV_ROWS,
  kParamCount = PV_MOSAIC_PARAM_COUNT
};
using WarpParams = std::array<float, kParamCount>;

// What stays the same for every frame: the camera, its pose on the robot, the limits.
struct WarpSetup {
  CameraModel camera;
  Extrinsics extrinsics;
  double max_range = 0;  // metres from the camera's foot point on the ground
  double feather = 0;    // ramp of the feathering weight, frame pixels from the region's border
  // Largest squared radius of the undistorted rays of the region's border pixels: ground points
  // beyond it are outside the field of view, where the polynomial distortion model can fold back
  // into the image.
  double max_radius2 = 0;
};
// Fills max_radius2 from the camera; throws InvalidArgument for a non-positive range, feather or
// camera height.
WarpSetup make_warp_setup(const CameraModel& camera, const Extrinsics& extrinsics, double max_range, double feather);

// The warp of one frame, at robot pose `pose` in the trajectory's frame, onto `window` of `grid`.
// Computed in double, stored as float.
WarpParams warp_params(const WarpSetup& setup, const SE2& pose, const MosaicGrid& grid, const Window& window);
// The same for a rolling-shutter camera (setup.camera.rolling_shutter_readout > 0): the robot's
// poses of the frame's first, middle and last rows' images (CameraModel::row_time; without a
// rolling shutter the first, which an exposure moves from the stamp). Each ground point is then
// sampled on the row that saw it: the row r with r = v(H(r / (rows - 1))), H(s) the quadratic
// through the three rows' homographies (exact to 1e-5 px for a turn of 0.1 rad over the
// readout), solved in the kernel by two fixed-point steps and Aitken's extrapolation.
WarpParams warp_params(const WarpSetup& setup, const std::array<SE2, 3>& row_poses, const MosaicGrid& grid,
                       const Window& window);

// The plain C++ reference of the kernel: frame CV_8UC1 (the camera's size), output CV_32FC2
// (value, weight) of the window's size. A rolling shutter's row is found by plain fixed-point
// iteration run to convergence (not the kernel's Aitken step).
cv::Mat mosaic_warp_reference(const cv::Mat& frame, const WarpParams& params, int width, int height);

// The kernel on an OpenCL device. Buffers are kept and grown as needed. Not thread-safe.
class MosaicWarp {
 public:
  MosaicWarp(ocl::Runtime& runtime, int frame_width, int frame_height);
  ~MosaicWarp();
  MosaicWarp(const MosaicWarp&) = delete;
  MosaicWarp& operator=(const MosaicWarp&) = delete;
  // Uploads the frame (CV_8UC1 of the size given at construction), runs the warp over a width x
  // height window and reads the result back into *out (CV_32FC2, reallocated as needed).
  void run(const cv::Mat& frame, const WarpParams& params, int width, int height, cv::Mat* out);
  // The -D options the program is built with (registered for `planarvo kernels --export`).
  static std::string build_options();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace planarvo::mosaic
