// The rolling shutter's geometry: a CMOS sensor reads its rows one after another, row r of H at
// stamp + r / (H - 1) * CameraModel::rolling_shutter_readout (docs/conventions.md), so a camera
// in motion sees each row from another pose. The image pipeline takes it out before anything
// else looks at the frame: it resamples the camera frame into the undistorted image a global
// shutter would have taken at the stamp (what the tracker, the pyramid and everything after
// them assume), given the robot's velocity over the readout.
//
// The model (constant velocity within a frame, on SE(2)): the robot pose at row r's read time
// is T(stamp) exp(tau_r xi), tau_r = r / (H - 1) * readout, xi = (vx, vy, omega) the robot's
// twist in its own frame, per second. A ground point seen at undistorted pixel p of the
// stamp's image is then seen by the camera of row r at q = H_r p, H_r the ground homography
// (core/extrinsics.h) of the motion exp(tau_r xi). The sensor row that sees it is the
// distorted row of q (the undistortion map's source row), so r solves r = row(H_r p): a fixed
// point. Plain iteration from the global shutter's row shrinks the error by the image's speed in
// rows per row time at each step (0.05-0.3: at 2500 px/s and a 30 ms readout of 480 rows it is
// 0.16, and three steps would leave a 75-row shear's error at 0.3 rows); the function is so
// nearly linear in r that Aitken's extrapolation from two steps (aitken()) lands within 1e-3 rows,
// and the sample is taken at that row.
#pragma once
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/extrinsics.h"
#include "image/camera.h"
#include "image/undistort.h"

namespace planarvo {

// Per sensor row r (0..height-1), the homography H_r from the stamp's undistorted pixels to
// row r's undistorted pixels, row-major, 9 floats each (H_r(2, 2) = 1). Between rows the
// homographies are interpolated linearly (rows are a few tens of microseconds apart).
struct RowWarp {
  int height = 0;
  std::vector<float> h;  // height * 9

  // Every row's homography the identity: a global shutter, or a camera at rest.
  bool identity() const;
};

// The identity for a camera of `height` rows.
RowWarp identity_row_warp(int height);

// The row warp of `camera` (its K, height and rolling_shutter_readout) on the robot at
// `extrinsics`, moving with `twist` (vx, vy, omega; m/s and rad/s in the robot frame). The
// identity for a global shutter. InvalidArgument when the twist is not finite.
RowWarp rolling_shutter_warp(const CameraModel& camera, const Extrinsics& extrinsics, const Eigen::Vector3d& twist);

// Aitken's delta-squared extrapolation of the iterates r0, r1 = f(r0), r2 = f(r1) of a fixed
// point: r2 - (r2 - r1)^2 / ((r2 - r1) - (r1 - r0)), clamped to [0, last_row]; r2 itself unless
// the steps shrink by at least 10 % and their difference exceeds 1e-4 (float noise). The kernel's
// arithmetic.
float aitken(float r0, float r1, float r2, float last_row);

// Plain C++ reference of the pipeline's rolling-shutter undistortion (kernel
// `undistort_rolling`), in the kernel's float arithmetic: per output pixel p of the
// undistorted image, with f(r) = s.y clamped to [0, H - 1] where s(r) is the map bilinearly
// interpolated at q = H_r p (its source coordinate: the map's cells clamped to the image,
// extrapolated beyond): r0 = the map's row at p (clamped), r1 = f(r0), r2 = f(r1),
// s = s(aitken(r0, r1, r2)); then gray sampled
// bilinearly at s as remap_bilinear samples (s inside the camera's region of interest: x <= s.x
// <= x + width - 1, the same in y), kInvalidIntensity (image/pipeline.h) where it is not.
// With the identity warp this is undistort_reference exactly. gray: CV_8UC1 of the camera's
// size; InvalidArgument otherwise or when the warp's height is not the camera's.
cv::Mat undistort_rolling_reference(const cv::Mat& gray, const CameraModel& camera, const UndistortMap& map,
                                    const RowWarp& warp);

}  // namespace planarvo
