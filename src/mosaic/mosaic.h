// The floor mosaic: an image of the ground built from a data set's frames and the robot's poses
// (a tracked trajectory), placed on a metric grid as ROS map_server places a map
// (src/mosaic/README.md). Each frame is warped onto the ground on the device (mosaic_warp.h),
// corrected by a gain estimated against the mosaic built so far, and blended with feathering
// weights into tiles that are allocated where frames fall and finished (to 8 bits) as soon as the
// last frame that sees them has been added, so memory follows the area in view, not the drive.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/extrinsics.h"
#include "core/se2.h"
#include "io/dataset/dataset.h"
#include "mosaic/mosaic_warp.h"
#include "ocl/runtime.h"

namespace planarvo::mosaic {

struct MosaicOptions {
  double resolution = 0.001;  // metres per mosaic pixel
  // Pixels whose ground point lies farther than this from the camera's foot point are not used
  // (metres); 0: 4 x the camera height. Far pixels see the ground at a coarser scale than near ones.
  double max_range = 0;
  // A frame is used once the camera's foot point has moved this far (metres) or the robot has
  // turned 5 degrees since the last frame used; 0: an eighth of the shorter side of the ground
  // the camera sees; negative: every frame.
  double frame_spacing = 0;
  // Feathering ramp, as a fraction of the region of interest's shorter side: a pixel's weight
  // rises linearly from the region's border over this distance.
  double feather = 0.25;
  bool estimate_gain = true;  // a gain per frame against the mosaic built so far
  int max_side = 20000;       // a mosaic larger than this on a side is refused (InvalidInput)
  int tile_size = 256;
  // Extrinsics outside core/extrinsics.h's plausible ranges (millimetres for metres, degrees for
  // radians) are refused (InvalidArgument naming the likely mistake) unless this is set.
  bool accept_unusual_extrinsics = false;
  // fraction done, stage; returns false to cancel (Error(Cancelled)).
  std::function<bool(double, const char*)> progress;
};

// A robot pose in the trajectory's frame at a data-set frame.
struct PosedFrame {
  int64_t frame = 0;
  SE2 pose;
};

struct MosaicStats {
  int64_t frames_given = 0, frames_used = 0;
  int64_t covered_pixels = 0;
  double gain_min = 1, gain_max = 1;
  int64_t peak_tile_bytes = 0;  // float accumulators held at once
  // Decoding runs on a second thread, one frame ahead: seconds_decode is its time, which overlaps
  // the warp and the blending.
  double seconds_decode = 0, seconds_warp = 0, seconds_blend = 0, seconds_total = 0;
};

struct Mosaic {
  MosaicGrid grid;
  cv::Mat image;  // CV_8UC1, grid.height x grid.width: 0 where no frame saw the ground, else 1..255
  MosaicStats stats;
};

// The data-set frame of each trajectory time: the frame whose time is within the tolerance
// (1 ms, or a quarter of the shortest frame interval when that is less). Throws InvalidInput
// naming the first trajectory entry (0-based index and time) that has no frame, or an empty
// trajectory.
std::vector<int64_t> match_frames(const std::vector<double>& frame_times, const std::vector<double>& times);

// Builds the mosaic of the frames at their poses. Throws InvalidInput for no poses or a mosaic
// larger than options.max_side on a side (naming the size it would be), InvalidArgument for bad
// options.
Mosaic build_mosaic(ocl::Runtime& runtime, io::Dataset& dataset, const Extrinsics& extrinsics,
                    const std::vector<PosedFrame>& frames, const MosaicOptions& options);

// Writes the image (any format cv::imwrite knows by the extension; PNG is lossless) and, beside it
// with the same stem and .yaml, the map_server description: image, resolution, origin
// [x, y, yaw], mode trinary, negate 0, occupied_thresh 1.0 and free_thresh 0.998, so that map_server
// (and nav2's) loads every seen pixel as free and every unseen one as unknown
// (docs/formats.md, "Floor mosaic"). Throws Error(Io) naming the file.
void save_mosaic(const Mosaic& mosaic, const std::string& image_path);

// The image for an ordinary viewer: the seen pixels' grey levels from their 1st to their 99th
// percentile stretched linearly over 1..255 (a floor's picture spans a few grey levels); unseen
// stays 0.
cv::Mat contrast_preview(const cv::Mat& image);
// Writes contrast_preview(mosaic.image) to path (format by extension), complete or not at all.
void save_preview(const Mosaic& mosaic, const std::string& path);

}  // namespace planarvo::mosaic
