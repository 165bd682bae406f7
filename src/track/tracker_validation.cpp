#include "track/tracker_validation.h"

#include <cmath>
#include <string>

#include <Eigen/LU>

#include "core/error.h"
#include "image/pyramid.h"

namespace planarvo::track {
namespace {

// The fewest pixels on a side of the coarsest pyramid level the tracker accepts.
constexpr int kMinCoarsestSide = 4;

// Some of the image (a 9 x 9 grid of undistorted pixels) looks at least 0.5 degrees below the
// horizon: the ground plane is in view. A camera pitched to look up sees none of it, and every
// frame would be Lost (or, with a sky texture, Ok and meaningless).
bool sees_the_ground(const CameraModel& c, const Extrinsics& e) {
  const Eigen::Vector3d n = e.plane_normal_camera();  // ground points X: n.X = -z
  const Eigen::Matrix3d Kinv = c.K().inverse();
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 8; ++j) {
      const Eigen::Vector3d d = (Kinv * Eigen::Vector3d(c.width * i / 8.0, c.height * j / 8.0, 1.0)).normalized();
      if (n.dot(d) < -std::sin(0.5 * M_PI / 180.0)) return true;
    }
  return false;
}

}  // namespace

CameraModel validated_tracker_camera(const CameraModel& c, const Extrinsics& e, const TrackerOptions& o) {
  if (o.levels < 1 || o.levels > kMaxLevels)
    throw_invalid_argument("TrackerOptions::levels must be 1.." + std::to_string(kMaxLevels));
  if (!(e.z > 0.0)) throw_invalid_argument("Tracker: the camera height z must be positive");
  if (!e.finite())
    throw_invalid_argument("Tracker: the extrinsics must be finite numbers");
  if (!o.accept_unusual_extrinsics) check_plausible_extrinsics(e, "Tracker: the extrinsics");
  if (!sees_the_ground(c, e))
    throw_invalid_argument("Tracker: with these extrinsics (roll " + std::to_string(e.roll) + ", pitch " +
                           std::to_string(e.pitch) + " rad) no part of the image looks below the horizon: the "
                           "camera does not see the ground (angles in radians, not degrees?)");
  for (int b : o.select_blocks)
    if (b < 0 || b > 16) throw_invalid_argument("TrackerOptions::select_blocks must be 0..16");
  if (o.auto_finer_block < 0 || o.auto_finer_block > 16)
    throw_invalid_argument("TrackerOptions::auto_finer_block must be 0..16");
  if (o.auto_coarse_block < 0 || o.auto_coarse_block > 16)
    throw_invalid_argument("TrackerOptions::auto_coarse_block must be 0..16");
  if (!(o.rolling_shutter_tolerance_px > 0.0))
    throw_invalid_argument("TrackerOptions::rolling_shutter_tolerance_px must be positive");
  if (!(o.keyframe_scale_change > 0.0))
    throw_invalid_argument("TrackerOptions::keyframe_scale_change must be positive");
  if (!(o.covariance_step_fraction >= 0.0))
    throw_invalid_argument("the tracker's covariance step fraction must be 0 or more");
  if (!(o.consecutive_alignment_correlation >= 0.0 && o.consecutive_alignment_correlation <= 0.5))
    throw_invalid_argument("the tracker's consecutive alignment correlation must be within [0, 0.5]");
  const MotionSearchOptions& so = o.search;
  if (!(so.max_shift >= 0.0 && so.max_shift <= 1.0) || !(so.grid_px >= 0.25) ||
      !(so.max_rotation >= 0.0 && so.max_rotation <= 0.5) || so.max_pixels < 16 || so.max_candidates < 1 ||
      !(so.min_overlap >= 0.0 && so.min_overlap <= 1.0) || !(so.max_ambiguity > 0.0 && so.max_ambiguity <= 1.0))
    throw_invalid_argument("TrackerOptions::search: max_shift in [0, 1], grid_px >= 0.25, max_rotation in [0, 0.5] rad, "
                           "max_pixels >= 16, max_candidates >= 1, min_overlap in [0, 1], max_ambiguity in (0, 1]");
  c.validate("Tracker camera");
  // The coarsest level must hold a few pixels for the alignment to work on (issue 27: a 1x1
  // camera failed inside the aligner with an internal message).
  const int coarsest_w = level_size(c.width, o.levels - 1), coarsest_h = level_size(c.height, o.levels - 1);
  if (coarsest_w < kMinCoarsestSide || coarsest_h < kMinCoarsestSide)
    throw_invalid_argument("Tracker: a " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                           " image is too small for " + std::to_string(o.levels) +
                           " pyramid levels: the coarsest would be " + std::to_string(coarsest_w) + "x" +
                           std::to_string(coarsest_h) + " pixels, and the tracker needs " +
                           std::to_string(kMinCoarsestSide) + " on a side (fewer levels, or a larger image)");
  return c;
}

}  // namespace planarvo::track
