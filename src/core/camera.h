// The pinhole camera with OpenCV's radial-tangential distortion (k1 k2 p1 p2 k3), exactly as
// cv::undistortPoints / cv::initUndistortRectifyMap define it. Pixel (0,0) is the centre of the
// top-left pixel. "Normalised" coordinates are (X/Z, Y/Z) of a camera-frame point.
#pragma once
#include <Eigen/Core>

namespace planarvo {

// A rectangle of camera-image pixels: columns x .. x + width - 1, rows y .. y + height - 1.
// Zero width or height: none given (the whole image).
struct PixelRegion {
  int x = 0, y = 0, width = 0, height = 0;
  bool empty() const { return width <= 0 || height <= 0; }
  bool operator==(const PixelRegion& o) const {
    return x == o.x && y == o.y && width == o.width && height == o.height;
  }
};

// Calls f(u, v) (ints) for the pixels on the border of region r: the top and bottom rows, then
// the left and right columns, every `step` pixels from the first (step 1: every border pixel).
template <class F>
void for_each_border_pixel(const PixelRegion& r, int step, F&& f) {
  for (int u = r.x; u < r.x + r.width; u += step) {
    f(u, r.y);
    f(u, r.y + r.height - 1);
  }
  for (int v = r.y; v < r.y + r.height; v += step) {
    f(r.x, v);
    f(r.x + r.width - 1, v);
  }
}

// The smallest region of interest a camera may have, pixels per side.
inline constexpr int kMinRegionSide = 16;

struct CameraModel {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  // The region of interest: the pixels of the camera image that see the ground the engine may
  // use (not the horizon, the vehicle's bumper, the sidewalk). Everything the engine computes
  // from an image treats pixels outside it as having no value, through the undistortion map
  // (image/undistort.h). Empty: the whole image.
  PixelRegion roi;
  // Rolling shutter: seconds from reading the first image row to reading the last (camera.yaml's
  // rolling_shutter_readout); 0 = global shutter. A frame's stamp is when its first row is read:
  // row r of H is read at stamp + r / (H - 1) * rolling_shutter_readout (docs/conventions.md).
  double rolling_shutter_readout = 0;
  // Exposure: seconds each row integrates the scene before it is read (camera.yaml's
  // exposure_time); 0 = not modelled. At constant velocity a row exposed over [t_r - E, t_r] is,
  // blurred, the sharp image of t_r - E / 2: what the engine models (row_time).
  double exposure_time = 0;
  // The time row r's image stands for, relative to the frame's stamp: its read time less half
  // the exposure, r / (H - 1) * rolling_shutter_readout - exposure_time / 2 (r may be fractional).
  double row_time(double r) const;
  // The mean of row_time over the rows: (rolling_shutter_readout - exposure_time) / 2.
  double mean_row_time() const { return 0.5 * (rolling_shutter_readout - exposure_time); }
  // Not every row's image stands for the stamp: a rolling shutter, or an exposure.
  bool timed_rows() const { return rolling_shutter_readout > 0 || exposure_time > 0; }
  // The region of interest, or the whole image when none is given.
  PixelRegion region() const { return roi.empty() ? PixelRegion{0, 0, width, height} : roi; }

  Eigen::Matrix3d K() const;
  bool has_distortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }

  // Undistorted normalised -> distorted normalised (OpenCV's forward model).
  Eigen::Vector2d distort(const Eigen::Vector2d& xn) const;
  // Distorted normalised -> undistorted normalised, by Newton's method to machine precision
  // (converges for the distortions real lenses have; see camera.cpp).
  Eigen::Vector2d undistort(const Eigen::Vector2d& xd) const;

  // Camera-frame point -> distorted pixel.
  Eigen::Vector2d project(const Eigen::Vector3d& X) const;
  // Distorted pixel -> undistorted normalised coordinates (the ray (x, y, 1)).
  Eigen::Vector2d unproject(const Eigen::Vector2d& pixel) const;

  // Throws InvalidInput (naming `what`, e.g. the file) when sizes or focal lengths are not
  // positive or a value is not finite, the rolling shutter readout or the exposure is negative,
  // or the region of interest is not inside the image or is smaller than kMinRegionSide pixels on
  // a side.
  void validate(const char* what) const;
};

}  // namespace planarvo
