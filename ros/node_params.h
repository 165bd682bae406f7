// planarvo_node's parameters (ros/README.md): read from the private namespace and checked before
// anything else starts, so that a bad value is one error naming it, not a crash later.
#pragma once
#include <string>

#include <planarvo/planarvo.h>

namespace ros {
class NodeHandle;
}

namespace planarvo_node {

struct NodeParams {
  std::string camera;      // ~camera: camera.yaml; "" = from the camera_info topic
  std::string extrinsics;  // ~extrinsics: extrinsics.yaml; "" = none (calibration only)
  // The OpenCL context, as the CLI's --device, --cache-dir, --kernel-binaries.
  std::string device, cache_dir, kernel_binaries;
  bool prepare_kernels = true;  // ~prepare_kernels: build the kernels before subscribing
  std::string odom_frame = "odom", base_frame = "base_link";
  bool publish_tf = true;
  planarvo_tracker_options tracker{};  // ~levels, ~finest_level, ~level0_subsample, ~max_iterations,
                                       // ~keyframe_overlap, with the library's defaults
  // ~flat_field: a known flat field (planarvo_tracker_options.flat_field); "" = learnt. The
  // tracker's options point at it only where the tracker is made (tracker.flat_field stays NULL
  // here, so that a copy of NodeParams holds no pointer into another).
  std::string flat_field;
  // ~readout_time: the camera's rolling-shutter readout in seconds (first row's read to the
  // last's), overriding the camera's (~camera's rolling_shutter_readout; camera_info has none, so
  // 0); -1 = the camera's.
  double readout_time = -1;
  // ~exposure_time: the camera's exposure in seconds, overriding the camera's (~camera's
  // exposure_time; camera_info has none, so 0); -1 = the camera's.
  double exposure_time = -1;
  int queue_size = 100;    // ~queue_size: the image subscriber's roscpp queue
  int max_pending = 300;   // ~max_pending: frames waiting for the tracker before the oldest is dropped
  double drain_seconds = 10;  // ~drain_seconds: on shutdown, time to finish the frames still queued
  // The live calibration (~calibrate): frames with the wheel odometry interpolated to their times.
  bool calibrate = false;
  std::string calibration_output;  // ~calibration_output: the extrinsics file written
  int calibration_frames = 0;      // ~calibration_frames: finish after this many frames; 0 = on shutdown
  double calibration_height = 0;   // ~calibration_height: the camera height when known (held); 0 = estimated
  double calibration_odom_wait = 2.0;  // ~calibration_odom_wait: seconds of frames held for odometry
  // ~force: accept extrinsics (and a calibration height) outside the plausible ranges (an offset
  // over 20 m, a height over 5 m, an angle over a turn: most likely millimetres or degrees), for an
  // unusual rig (planarvo_tracker_options.accept_unusual_extrinsics).
  bool force = false;
};

// Reads and checks every parameter; false (after ROS_FATAL naming the bad one) when one is bad.
bool read_params(const ros::NodeHandle& private_nh, NodeParams* params);

}  // namespace planarvo_node
