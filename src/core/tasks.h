// The engine's tasks, named as the tool's commands that run them: what the layers register their
// kernel programs' variants for (ocl::Runtime::register_build_options, which takes them as opaque
// names), and what `planarvo kernels --export DIR --for TASK` and
// planarvo_context_export_kernels_for select by.
#pragma once

namespace planarvo::tasks {

inline constexpr const char* kTrack = "track";          // the tracker: planarvo_tracker_*
inline constexpr const char* kCalibrate = "calibrate";  // roll and pitch, then the tracker
inline constexpr const char* kSimulate = "simulate";    // the simulator's renderer
inline constexpr const char* kMosaic = "mosaic";        // the floor mosaic: planarvo_mosaic_*

}  // namespace planarvo::tasks
