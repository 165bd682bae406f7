// The rolling shutter's geometry: a CMOS sensor reads its rows one after another, row r of H at
// stamp + r / (H - 1) * CameraModel::rolling_shutter_readout (docs/conventions.md), so a camera
// in motion sees each row from another pose; an exposure E integrates each row over the E before
// its read, which at constant velocity is the sharp image of E / 2 earlier (blurred). The image
// pipeline takes both out before anything else looks at the frame: it resamples the camera
// frame into the undistorted image an instantaneous global shutter would have taken at the
// stamp (what the tracker, the pyramid and everything after them assume), given the robot's
// velocity over the frame.
//
// The model (constant velocity within a frame, on SE(2)): the robot pose of row r's image is
// T(stamp) exp(tau_r xi), tau_r = CameraModel::row_time(r) = r / (H - 1) * readout - E / 2 (an
// exposure alone: every row at -E / 2, a rigid shift of the image), xi = (vx, vy, omega) the robot's
// twist in its own frame, per second. A ground point seen at undistorted pixel p of the
// stamp's image is then seen by the camera of row r at q = H_r p, H_r the ground homography
// (core/extrinsics.h) of the motion exp(tau_r xi). The sensor row that sees it is the row of
// q's distorted pixel, so r solves r = row(H_r p): a fixed point. Plain iteration from the
// global shutter's row shrinks the error by the image's speed in rows per row time at each step
// (0.05-0.3: at 2500 px/s and a 30 ms readout of 480 rows it is 0.16), so Aitken's
// extrapolation is applied every two steps, until the row moves by under 1e-5 rows.
//
// The source pixel of p is then s(p) = distort(H_r p), which differs from the global shutter's
// (the undistortion map's) by a smooth field: the warp is that difference on a grid of nodes
// every RowWarp::step pixels, solved in double on the host (every second node column and row,
// the others filled in by cubics through them: 0.1 ms at 640x480), and the kernel adds it,
// interpolated bilinearly, to the map. The field is smooth (the solver continues it beyond the sensor's rows,
// so that nodes just outside the image do not bend it) but not linear: the rows' times enter it
// quadratically through the rotation and the perspective. A 16 px grid interpolates it within
// 0.04 px for a 75 px shear (1.5 m/s and 1.2 rad/s at 0.18 m, a 30 ms readout; 8 px: 0.01 px, 4x
// the host's time), less in proportion below that; the tracker's accuracy measured the same with
// either.
#pragma once
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/extrinsics.h"
#include "core/camera.h"
#include "image/undistort.h"

namespace planarvo {

inline constexpr int kRowWarpStep = 16;

// The rolling shutter's displacement of each undistorted pixel's source coordinate, relative to
// the global shutter's (UndistortMap), on a grid: node (i, j) at pixel (i * step, j * step),
// i < nodes_x = (width - 1) / step + 2, j < nodes_y = (height - 1) / step + 2 (the last nodes
// lie at or beyond the image's last pixel), (dx, dy) interleaved, row-major. The kernel needs
// step >= 8 (eight pixels of a work-item span at most two cells).
struct RowWarp {
  int width = 0, height = 0;  // the image's
  int step = kRowWarpStep;
  int nodes_x = 0, nodes_y = 0;
  std::vector<float> delta;  // 2 * nodes_x * nodes_y
  // Where the light fixed to the camera is, on the same grid: pixel p's value is read from camera
  // pixel distort(H_r p), the pixel that the global shutter's undistortion puts at q = H_r p, so
  // the photometric model (photometric.h, per undistorted pixel of a global shutter) has that
  // pixel's light at q. light = q - p (undistorted pixels), (dx, dy) interleaved, as delta.
  std::vector<float> light;  // 2 * nodes_x * nodes_y

  // Every node's displacement zero: a global shutter, or a camera at rest.
  bool identity() const;
};

// One of the warp's fields (RowWarp::delta or RowWarp::light) at pixel (u, v), interpolated as
// the kernels interpolate it, in their float arithmetic: bilinearly at (u / step, v / step), the
// cell clamped to the grid, between the node rows first.
Eigen::Vector2f row_warp_at(const RowWarp& warp, const std::vector<float>& field, int u, int v);

// The identity for a width x height camera (InvalidArgument for sizes < 1 or step < 8).
RowWarp identity_row_warp(int width, int height, int step = kRowWarpStep);

// The warp of `camera` (its K, distortion, size and rolling_shutter_readout) on the robot at
// `extrinsics`, moving with `twist` (vx, vy, omega; m/s and rad/s in the robot frame). The
// identity for a camera whose rows all stand for the stamp (CameraModel::timed_rows) or a zero
// twist. InvalidArgument when the twist is not finite.
RowWarp rolling_shutter_warp(const CameraModel& camera, const Extrinsics& extrinsics, const Eigen::Vector3d& twist,
                             int step = kRowWarpStep);

// The source coordinate of undistorted pixel (u, v) under the rolling shutter, solved exactly (in
// double, per pixel, to 1e-5 rows), without the grid: the independent reference the grid is
// checked against.
Eigen::Vector2d rolling_shutter_source(const CameraModel& camera, const Extrinsics& extrinsics,
                                       const Eigen::Vector3d& twist, double u, double v);

// Plain C++ reference of the pipeline's rolling-shutter undistortion (kernel
// `undistort_rolling`), in the kernel's float arithmetic: per output pixel p = (u, v), the warp's
// displacement interpolated bilinearly at (u / step, v / step) (cells clamped to the grid;
// between the node rows first) is
// added to the map's coordinate; gray is sampled there bilinearly as remap_bilinear samples (the
// coordinate inside the camera's region of interest: x <= s.x <= x + width - 1, the same in y),
// kInvalidIntensity (image/pipeline.h) where it is not. With the identity warp this is
// undistort_reference exactly. gray: CV_8UC1 of the camera's size; InvalidArgument otherwise or
// when the warp is not the camera's size.
cv::Mat undistort_rolling_reference(const cv::Mat& gray, const CameraModel& camera, const UndistortMap& map,
                                    const RowWarp& warp);

}  // namespace planarvo
