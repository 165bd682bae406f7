// A rolling shutter's readout time from the drive itself: no anchor estimates it, and a camera
// file rarely says it.
//
// Row r of a frame is read at stamp + r/(H-1)·readout (docs/conventions.md), so a moving camera
// sees the floor sheared by velocity × readout. The tracker takes the shear out with the readout
// it is told (image/rolling_shutter.h); told the wrong one, what is left is a non-rigid
// distortion that the 3-DoF planar warp cannot follow, and the alignment's robust residual scale
// grows. Frame i's residual variance is close to n_i² + c_i·(r − r*)², where r* is the true
// readout and c_i grows with the frame's speed squared: the sum over frames is smallest at r*.
//
// A first pass tracks every frame (the tracker told a readout: the guess, or max/2) and keeps
// each frame's velocity. The estimate then tracks a few windows of consecutive frames (the
// fastest of the drive) with a handful of candidate readouts, narrowing a bracket on [0, max],
// each frame undistorted with its twist interpolated between the first pass's velocities before
// and after it (offline, so no extrapolation), and the tracker run on those pyramids. The
// residual between a frame and its keyframe measures the readout error times the difference of
// their twists, so twists extrapolated as the live tracker must (track/readout_twist.h) biased
// the estimate 4-16 % low. It then fits each frame's residual variance with a parabola in r over
// the candidates next to the best one.
// The estimate is the minimum of their sum; its σ is the sandwich (M-estimator) variance
// Σ_g s_g² / (Σ_i 2 c_i)², with s_g the slope of the summed parabolas of a cluster of consecutive
// frames at the estimate (frames share their keyframe, so they are not independent).
#pragma once
#include <array>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/extrinsics.h"
#include "core/camera.h"
#include "track/tracker.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::calib {

struct ReadoutEstimateOptions {
  int window_frames = 30;  // consecutive frames per window (the tracker restarts at each)
  int windows = 4;         // the fastest windows of the first pass
  double max_readout = 0;  // the bracket's top, seconds; 0: 0.95 × the frames' median interval
  // A readout already estimated (seconds; negative: none): the search starts at it and its
  // neighbours at max/8 instead of bracketing [0, max].
  double guess = -1.0;
  int cluster_frames = 10;  // frames per cluster in the sandwich variance
  // An estimate below this many σ is reported but the camera is taken as a global shutter.
  double zero_below_sigmas = 2.0;
  track::TrackerOptions tracker;
  // Called with the fraction done; false cancels (Error(Cancelled)).
  std::function<bool(double fraction)> progress;
};

struct ReadoutEstimate {
  bool ok = false;
  std::string reason;  // why not ok: too few frames, no motion to shear the images
  double estimate = 0.0;  // seconds, in [0, max]
  double sigma = 0.0;     // its standard deviation, seconds
  double readout = 0.0;   // what to use: the estimate, or 0 when it is within zero_below_sigmas σ of 0
  double max_readout = 0.0;
  int frames = 0;       // frames whose residuals entered the fit
  int evaluations = 0;  // candidate readouts tracked
  // Each candidate: (readout s, mean residual variance over the windows' frames, grey levels²).
  std::vector<std::array<double, 2>> curve;
  double seconds = 0.0;
};

// frames: 8-bit grey images of the camera's size with their stamps (seconds, increasing).
// camera_frame: the extrinsics the tracker uses (the calibration's: the camera's roll and pitch
// at height 1). The camera's own rolling_shutter_readout is ignored.
ReadoutEstimate estimate_readout(ocl::Runtime& runtime, const CameraModel& camera, const Extrinsics& camera_frame,
                                 const std::vector<cv::Mat>& frames, const std::vector<double>& stamps,
                                 const ReadoutEstimateOptions& options = {});

}  // namespace planarvo::calib
