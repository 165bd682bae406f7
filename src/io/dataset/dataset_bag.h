// Internal to src/io: a ROS 1 bag or MCAP file as a data set's frames, camera, odometry and
// ground truth (io/dataset.h opens it when its path is such a file; docs/formats.md, "ROS bags").
//
// Time: every stamp is integer nanoseconds until it is made relative to the first frame's
// (after sorting), and only then converted to seconds, so a base time of 1.7e9 s costs no
// precision. Frames are sorted by their time (a header stamp, or the receive time); two frames
// with the same time are an error, as are images whose size disagrees with the camera. Odometry
// and ground truth are sorted by time too; their pose is x, y and the yaw of the orientation
// quaternion (z, roll and pitch are not used).
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera.h"
#include "io/formats.h"

namespace planarvo::io {

struct BagDatasetOptions {
  std::string image_topic;        // empty: the bag's only image topic
  std::string camera_info_topic;  // these two empty: the bag's only CameraInfo topic
  std::string camera_yaml;
  std::string odometry_topic;     // empty: the only nav_msgs/Odometry topic but groundtruth_topic, else none
  std::string groundtruth_topic;  // empty: none
  bool use_receive_time = false;  // time by the recorder's receive time, not header stamps
};

// The file to read for `path`: path itself when it is a ROS 1 bag or an MCAP file; the MCAP file
// inside it when it is a ROS 2 bag directory (`ros2 bag record` writes metadata.yaml and
// NAME_0.mcap); none otherwise. A ROS 2 bag directory split into several files, or stored in
// SQLite (.db3), is InvalidInput saying how to convert it.
std::optional<std::string> bag_file_for(const std::string& path);

namespace detail {

class BagSource {
 public:
  // report(fraction, stage) is called while indexing; it throws to cancel.
  BagSource(const std::string& path, const BagDatasetOptions& options, bool verify,
            const std::function<void(double, const char*)>& report);
  ~BagSource();

  const CameraModel& camera() const { return camera_; }
  // Camera description for messages: "the camera info on /camera/camera_info" or the yaml path.
  const std::string& camera_source() const { return camera_source_; }
  // The camera file (--camera) gave rolling_shutter_readout; a CameraInfo never does.
  bool readout_given() const { return readout_given_; }
  int64_t time_origin_ns() const { return origin_ns_; }
  // Frame times in seconds after the first, frame paths empty.
  const std::vector<FrameEntry>& frames() const { return frames_; }
  const std::vector<StampedPose>& odometry() const { return odometry_; }
  const std::vector<StampedPose>& groundtruth() const { return groundtruth_; }

  cv::Mat frame(int64_t i);
  // "log.bag: /camera/image_raw message 12 of 600".
  std::string name(int64_t i) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  CameraModel camera_;
  std::string camera_source_;
  bool readout_given_ = false;
  int64_t origin_ns_ = 0;
  std::vector<FrameEntry> frames_;
  std::vector<StampedPose> odometry_, groundtruth_;
};

}  // namespace detail
}  // namespace planarvo::io
