// The camera's calibration from images to extrinsics (the paper's whole method, sections 5.1 and
// 5.2): a short drive in, six extrinsics with uncertainties out.
//   1. roll and pitch from the first frames with enough motion (track/roll_pitch.h);
//   2. the sequence tracked with that tilt at x = y = 0, z = 1, yaw = 0 (track/tracker.h): the
//      camera's planar motions in units of its height, with covariances (calib/motion_samples.h);
//   3. the graph calibration of x, y, height and yaw, against wheel odometry or from the
//      nonholonomic constraint with direction labels and a height given by hand
//      (graph/calibration/calibration.h);
//   4. the 6-DoF extrinsics with a 6x6 covariance (calib/extrinsics_estimate.h).
// Frames arrive one at a time (a data set, a camera stream): the frames of stage 1 are held on
// the host until the tilt is known and then tracked, so every frame of the drive is used once.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calib/extrinsics_estimate.h"
#include "calib/readout_estimate.h"
#include "calib/tilt_propagation.h"
#include "core/se2.h"
#include "graph/calibration/calibration.h"
#include "core/camera.h"
#include "track/roll_pitch.h"
#include "track/tracker.h"

namespace planarvo::ocl {
class Runtime;
}
namespace planarvo::io {
class Dataset;
}

namespace planarvo::calib {

struct PipelineOptions {
  // Stage 1. With estimate_roll_pitch false, roll and pitch are taken from `initial` (required
  // then) and not estimated. roll_pitch.max_frames is the number of frames the stage uses
  // (counted from the first in which the camera moves; 0: until its map is complete). At most
  // max_buffered_frames frames are held for it; then it estimates with what it has.
  bool estimate_roll_pitch = true;
  track::RollPitchOptions roll_pitch;
  int max_buffered_frames = 900;
  // Stage 2: the tracker (its extrinsics come from stage 1).
  track::TrackerOptions tracker;
  // Stage 3: the method, the height when it is given (fix_scale, fixed_scale: the nonholonomic
  // method needs it), the noise model and robustness. The odometry's noise model is estimated
  // from the drive (estimate_odometry_noise) unless turned off here.
  graph::CalibrationOptions graph = default_graph_options();
  // A starting guess of the extrinsics: its roll and pitch start stage 1 and its x, y, z, yaw
  // start stage 3 (otherwise stage 1 starts looking straight down and stage 3 from its closed
  // form).
  std::optional<Extrinsics> initial;
  // Initial extrinsics and a height given by hand outside core/extrinsics.h's plausible ranges
  // (most likely millimetres or degrees) are refused unless this is set.
  bool accept_unusual_extrinsics = false;
  // The rolling shutter's readout time (calib/readout_estimate.h). Off: the camera's
  // rolling_shutter_readout as it is. On: estimated from the first readout_frames frames (held
  // with stage 1's, so at most max_buffered_frames), after a first estimate of roll and pitch,
  // and used from stage 1 on (stage 1 runs again through it). IfUnknown: calibrate_dataset
  // estimates it when the data set's camera does not give it (io::Dataset::readout_given); a
  // CameraCalibrator, which gets a camera and not a file, takes IfUnknown as Off. Off by
  // default: a camera file without the key stays a global shutter unless the user asks, because
  // a small global-shutter camera can read as a few ms (320x240: 2.7 +- 0.3; calib/README.md).
  enum class Readout { Off, IfUnknown, On };
  Readout readout = Readout::Off;
  int readout_frames = 300;
  ReadoutEstimateOptions readout_estimate;
  // The tilt's uncertainty carried into x, y, height and yaw and their cross-covariance with roll
  // and pitch (calib/tilt_propagation.h: the tracker's tilt Jacobians, 0.6-1.2 ms a frame at
  // 640x480, and four more graph solves; a 20-s calibration takes 7-14 % longer). false: the
  // stages' errors are taken as independent.
  bool propagate_tilt = true;
  // Progress: fraction of the frames fed so far (calibrate_dataset; a stream's total is unknown)
  // and the stage; return false to cancel (Error(Cancelled)).
  std::function<bool(double fraction, const char* stage)> progress;

  static graph::CalibrationOptions default_graph_options();
};

struct PipelineReport {
  enum class Status {
    Ok,
    TooLittleTexture,  // stage 1: the frames could not be tracked
    TooLittleMotion,   // stage 1: the camera did not move enough for roll and pitch
    Unobservable,      // stage 3: the drive does not determine x, y, height or yaw (reason says)
    Failed,            // anything else that ran but failed (reason says)
  };
  Status status = Status::Failed;
  std::string reason;  // "" when Ok: what failed, and what would fix it
  ExtrinsicsEstimate extrinsics;
  track::RollPitchResult roll_pitch;  // stage 1 (status Ok and empty when not estimated)
  // The readout time's estimate (evaluations 0 when it was not estimated); the tracking used
  // readout.readout when it is ok, the camera's otherwise.
  ReadoutEstimate readout;
  double readout_used = 0.0;  // the readout time stages 1 and 2 used, seconds
  graph::CalibrationResult graph;     // stage 3 (when it ran)
  // d(x, y, scale, yaw) / d(roll, pitch) through stages 2 and 3 (calib/tilt_propagation.h); none
  // when not propagated.
  std::optional<Eigen::Matrix<double, 4, 2>> tilt_jacobian;
  std::vector<graph::MotionSample> samples;  // stage 2's output, stage 3's input
  struct Tracking {
    int frames = 0, ok = 0, degraded = 0, lost = 0, keyframes = 0;
    double engine_ms = 0.0;   // tracker time, pipeline included, all frames
    double median_ms = 0.0;   // per frame
  } tracking;
  struct Timings {            // wall seconds per stage
    double decode = 0.0;      // waiting for images (calibrate_dataset; io::Dataset reads ahead)
    double roll_pitch = 0.0;  // stage 1: its tracker and the joint alignment
    double readout = 0.0;     // the readout time's estimate
    double tracking = 0.0;    // stage 2
    double graph = 0.0;       // stage 3
    double tilt = 0.0;        // the tilt's uncertainty carried into stage 3 (propagate_tilt)
    double total = 0.0;
  } time;
  bool ok() const { return status == Status::Ok; }
};

const char* status_name(PipelineReport::Status s);

class CameraCalibrator {
 public:
  // camera: the distorted camera the frames come from. Throws InvalidArgument for options that
  // cannot work (estimate_roll_pitch off without `initial`, the nonholonomic method without a
  // fixed height).
  CameraCalibrator(ocl::Runtime& runtime, const CameraModel& camera, const PipelineOptions& options);
  ~CameraCalibrator();
  CameraCalibrator(const CameraCalibrator&) = delete;
  CameraCalibrator& operator=(const CameraCalibrator&) = delete;

  // A wheel-odometry sample, in time order (InvalidArgument when not after the one before or not
  // finite): frames given no pose of their own take the pose interpolated at their time
  // (io::interpolate_pose) from the samples given by then, none when those do not reach it.
  void add_odometry(double timestamp, const SE2& pose);

  // Frame k: 8-bit grey of the camera's size (rows stride bytes apart), its time, the robot's
  // wheel-odometry pose at that time (none: the odometry does not cover it, or add_odometry's
  // samples give it) and the direction label of the interval from the previous frame to this one.
  void add_frame(const uint8_t* gray, int width, int height, size_t stride, double timestamp,
                 const std::optional<SE2>& odometry_pose = std::nullopt,
                 const std::optional<int>& direction = std::nullopt);

  // Runs what is left (stage 1 if its map is still open, stage 3) and returns the report. Once.
  PipelineReport finish();

  // What the frames are going to now: "roll and pitch", "tracking", or "stopped" (stage 1 refused;
  // later frames are not used).
  const char* stage() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The whole pipeline over a data set: every frame, its odometry (odometry.txt) and direction
// label (direction.txt). Throws InvalidInput when the method's inputs are missing (odometry for
// the odometry method; direction labels or odometry, whose sign gives them, for the nonholonomic
// one) or a frame cannot be read.
PipelineReport calibrate_dataset(ocl::Runtime& runtime, io::Dataset& dataset, const PipelineOptions& options);

// Stage 2 on its own: every frame of the data set tracked with the given extrinsics (for the graph
// calibration of a camera, stage2_extrinsics), one sample per tracked interval with the data set's
// odometry and direction labels, through calibrate_dataset's loop. Progress as calibrate_dataset's
// (stage "tracking").
std::vector<graph::MotionSample> track_motions(ocl::Runtime& runtime, io::Dataset& dataset, const Extrinsics& extrinsics,
                                               const track::TrackerOptions& options,
                                               const std::function<bool(double, const char*)>& progress = {});

}  // namespace planarvo::calib
