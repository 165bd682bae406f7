// The tracker's residual image, for an outlier overlay (the paper's Figure 20): per keyframe
// pixel of one pyramid level, the last tracked frame's photometric residual against its
// keyframe at the final alignment, the Huber weight the robust norm gives it and whether the
// pixel is valid. Made on request by one pass of the fused kernel's DEBUG_OUTPUT variant
// (kernels/track/warp_reduce.cl: every pixel of the level, whatever subsampling the tracking used),
// so tracking itself runs no extra work and gives the same results.
#pragma once
#include <memory>
#include <vector>

#include <CL/opencl.hpp>
#include <Eigen/Core>

#include "core/body_attitude.h"
#include "core/extrinsics.h"
#include "core/se2.h"
#include "image/pyramid.h"
#include "track/warp_reduce.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::track {

// A frame's final alignment with its keyframe, as the tracker keeps it until the next frame.
struct AlignmentRecord {
  // Handles on the device pyramids aligned (the keyframe's, and the live frame's). The tracker
  // keeps their contents until its next frame (a frame that became the keyframe included).
  Pyramid reference, live;
  SE2 motion;                      // the live robot pose in the keyframe's robot frame
  double log_gain = 0, bias = 0;   // brightness: r = e^a I_l + b - I_r
  double huber_k = 0;              // the Huber threshold of the finest level tracked, grey levels
  int finest_level = 0;            // the finest level tracked
  // The local plane's attitudes of the keyframe and the live frame (zero: the rigid body).
  BodyAttitude reference_attitude, live_attitude;
};

struct ResidualImage {
  int level = 0;                // the pyramid level (0: full resolution)
  int width = 0, height = 0;    // its size (level_size of the camera's)
  // Row-major, width x height, one per keyframe pixel p of the level:
  std::vector<float> residual;   // r = e^a I_l(w(p)) + b - I_r(p), grey levels; 0 where invalid
  std::vector<float> weight;     // Huber weight: 1 for |r| <= k, k / |r| beyond; 0 where invalid
  std::vector<float> intensity;  // the keyframe's undistorted intensity I_r(p); NaN where it has none
  // Valid: the keyframe pixel is valid and its warp lands inside the live level, between four
  // valid live pixels (weight > 0 exactly then).
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();  // keyframe -> live pixels at this level
  double gain = 1, bias = 0;    // e^a and b of the final alignment
  double huber_k = 0;           // k, grey levels: AlignmentRecord::huber_k at every level
  int tracked_level = 0;        // the finest level the tracking aligned
  double valid = 0, inliers = 0;  // counts of valid pixels, and of those with |r| <= k
};

// The DEBUG_OUTPUT pass and its buffer, built on the first request.
class ResidualImager {
 public:
  // K: the camera matrix of level 0 (undistorted pinhole); kernel: the tracker's kernel options
  // (work-group shape; stats, selection and debug output are set here).
  ResidualImager(ocl::Runtime& runtime, const Eigen::Matrix3d& K, const WarpReduceOptions& kernel);
  ~ResidualImager();

  // The residual image of an alignment at `level`; InvalidArgument for a level either pyramid
  // lacks (or a live level below 2 x 2 pixels).
  void compute(const AlignmentRecord& alignment, const Extrinsics& extrinsics, int level, ResidualImage* out);
  // texture_residual(image) of texture_residual.h for that residual image, reduced on the device
  // (kernels/track/texture_residual.cl) instead of read back: the honest-status check of every frame.
  double texture_residual(const AlignmentRecord& alignment, const Extrinsics& extrinsics, int level);

  static WarpReduceOptions kernel_options(const WarpReduceOptions& tracker_kernel);

 private:
  ocl::Runtime& runtime_;
  Eigen::Matrix3d K_;
  // The DEBUG_OUTPUT pass into debug_ (checks the level); the warp's inputs.
  WarpInputs run_pass(const AlignmentRecord& alignment, const Extrinsics& extrinsics, int level, ReduceSums* sums);

  WarpReduce pass_;
  cl::Buffer debug_;
  size_t debug_capacity_ = 0;  // pixels
  std::vector<float> host_debug_, host_ref_;
  cl::Kernel texture_kernel_;  // texture_residual.cl
  cl::Buffer texture_partials_;
  size_t texture_capacity_ = 0;  // floats
  std::vector<float> host_texture_;
};

}  // namespace planarvo::track
