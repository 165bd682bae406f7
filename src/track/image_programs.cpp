// The image pipeline's programs as track's tasks run them: the tracker and the roll/pitch estimator
// (hence tracking and calibration) make their pipelines with image/'s default options, so those
// variants are registered for export with track's tasks before main() (`planarvo kernels --export
// --for track` exports them without a pipeline having been made). image/ names and builds its
// programs; which task needs them is said here, by the layer that runs them.
#include "core/tasks.h"
#include "image/pipeline.h"
#include "ocl/runtime.h"

namespace planarvo::track {
namespace {

const bool kImageDefaultsRegistered = [] {
  const std::vector<std::string> uses = {tasks::kTrack, tasks::kCalibrate};
  ocl::Runtime::register_build_options("undistort", ImagePipeline::undistort_build_options(), uses);
  ocl::Runtime::register_build_options("pyramid", ImagePipeline::pyramid_build_options(), uses);
  return true;
}();

}  // namespace
}  // namespace planarvo::track
