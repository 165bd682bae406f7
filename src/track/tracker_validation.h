// The tracker's checks of what it is made with (Tracker's constructor): its options (levels,
// subsampling, the search's grid, the covariance's constants), the extrinsics (finite, a positive
// height, some of the image below the horizon) and the camera (valid, large enough for the
// pyramid's coarsest level). Kept apart from the tracking itself.
#pragma once
#include "core/extrinsics.h"
#include "core/camera.h"
#include "track/tracker.h"

namespace planarvo::track {

// The camera, when the three are usable together; else Error(InvalidArgument) naming the first
// bad value and what would fix it.
CameraModel validated_tracker_camera(const CameraModel& camera, const Extrinsics& extrinsics,
                                     const TrackerOptions& options);

}  // namespace planarvo::track
