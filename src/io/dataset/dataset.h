// A data set directory (docs/formats.md): camera.yaml, frames.txt + images/ or a video,
// and the optional odometry, direction labels, ground truth and extrinsics. Everything but the
// image pixels is read and validated when the data set is opened; a bad file is
// Error(InvalidInput) naming the file (and line), never a crash and never silently skipped.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/se2.h"
#include "core/camera.h"
#include "io/dataset/dataset_bag.h"
#include "io/formats.h"

namespace planarvo::io {

// Called while opening with the fraction done (0..1) and what is being done; returning false
// cancels the open with Error(Cancelled).
using ProgressCallback = std::function<bool(double fraction, const char* stage)>;

struct DatasetOptions {
  // A video file standing in for images/ + frames.txt (which are then ignored), used as given
  // (relative to the current directory, not to the data set's). Empty: frames.txt.
  std::string video;
  // Decode every image (or video frame) while opening, so that an unreadable frame or one of
  // the wrong size is reported at open rather than when the frame is read.
  bool verify_images = false;
  // A listed image that does not exist is not an error at open (a stat per image finds it by
  // default); reading its frame throws InvalidInput, like an undecodable image.
  bool allow_missing_images = false;
  ProgressCallback progress;  // may be empty
  // When the path is a ROS 1 bag or an MCAP file: its topics and camera (io/dataset_bag.h).
  // Given any of them for a data set directory, opening fails (they would be ignored).
  BagDatasetOptions bag;
};

// Pose samples interpolated to time t (SE(2), linear in x, y and theta, the angle the shorter
// way round: interpolate_linear). Exactly a sample where t equals its time; none outside
// [first, last] sample time or when there are no samples. samples must be in time order.
std::optional<SE2> interpolate_pose(const std::vector<StampedPose>& samples, double t);

// The label whose interval contains time t: label k covers (t_{k-1}, t_k], the first label
// everything up to t_0; none after the last label. labels must be in time order.
std::optional<int> direction_at(const std::vector<DirectionLabel>& labels, double t);

class Dataset {
 public:
  // Opens and validates the data set in `directory`, or the ROS 1 bag or MCAP file at that path
  // (recognised by its first bytes), or the MCAP file of the ROS 2 bag directory at that path
  // (bag_file_for). Throws Error(InvalidInput) naming the file for anything
  // missing or malformed, Error(Cancelled) when the progress callback says so.
  explicit Dataset(const std::string& directory, DatasetOptions options = {});
  ~Dataset();
  Dataset(Dataset&&) noexcept;
  Dataset& operator=(Dataset&&) noexcept;
  Dataset(const Dataset&) = delete;
  Dataset& operator=(const Dataset&) = delete;

  const std::string& directory() const;
  const CameraModel& camera() const;
  // Replaces the camera's region of interest (camera.yaml's region_of_interest; empty: the whole
  // image). Throws InvalidInput, changing nothing, when it is not inside the image.
  void set_region_of_interest(const PixelRegion& roi);
  // Replaces the camera's rolling_shutter_readout (seconds). InvalidInput naming `where` when it
  // is negative, not finite or longer than the frames' median interval (check_readout).
  void set_rolling_shutter_readout(double seconds, const std::string& where);
  // The readout time was given: by the camera file's rolling_shutter_readout (0 included) or by
  // set_rolling_shutter_readout. Otherwise the camera is taken as a global shutter, and
  // `calibrate` estimates the readout (calib/pipeline.h, PipelineOptions::readout).
  bool readout_given() const;
  bool is_video() const;
  bool is_bag() const;
  // A bag's first frame's stamp in integer nanoseconds; timestamps are seconds after it. 0 for
  // a directory, whose timestamps are frames.txt's (or the video's).
  int64_t time_origin_ns() const;

  int64_t frame_count() const;  // at least 1
  double timestamp(int64_t i) const;
  // Frame times and paths as in frames.txt; for a video, the paths are empty.
  const std::vector<FrameEntry>& frames() const;
  // A name for frame i in messages: its image path, or "video.avi frame 12".
  std::string frame_source(int64_t i) const;

  // Frame i as CV_8UC1 of the camera's size; colour is converted to grey (OpenCV's BGR weights).
  // Images that are not 8-bit (16-bit PNG or TIFF, float) are rejected with Error(InvalidInput),
  // as are missing or undecodable files and frames of the wrong size. Decoding is not cached
  // for image files; for a video, the last few decoded frames are (see dataset.cpp on the cost
  // of reading a video out of order). Image files are read ahead: while frames are asked for in
  // order, the next one is decoded on a worker thread (its error, if any, thrown when it is asked
  // for). Not safe to call from two threads at once.
  cv::Mat frame(int64_t i);

  // Odometry (odometry.txt) and ground truth (groundtruth.txt) interpolated to frame i's time;
  // none without the file or outside its time span.
  bool has_odometry() const;
  const std::vector<StampedPose>& odometry() const;
  std::optional<SE2> odometry_at(int64_t i) const;
  bool has_groundtruth() const;
  const std::vector<StampedPose>& groundtruth() const;
  std::optional<SE2> groundtruth_at(int64_t i) const;

  // The direction label (direction.txt) of the interval from frame i-1 to frame i: the label
  // whose interval contains the interval's midpoint (direction_at). None for frame 0, without
  // the file, or after the last label.
  bool has_direction() const;
  const std::vector<DirectionLabel>& direction_labels() const;
  std::optional<int> direction_for_interval(int64_t i) const;

  // extrinsics.yaml and extrinsics_gt.yaml, when present.
  const std::optional<ExtrinsicsEstimate>& extrinsics() const;
  const std::optional<ExtrinsicsEstimate>& extrinsics_gt() const;

 private:
  struct Impl;
  void check_index(int64_t i, const char* what) const;
  void open_bag(const std::string& file, const DatasetOptions& options);
  std::unique_ptr<Impl> impl_;
};

}  // namespace planarvo::io
