#include "track/residual_image.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/tasks.h"
#include "ocl/runtime.h"
#include "track/texture_residual.h"
#include "track/warp_model.h"

namespace planarvo::track {

WarpReduceOptions ResidualImager::kernel_options(const WarpReduceOptions& tracker_kernel) {
  WarpReduceOptions k = tracker_kernel;
  k.stats = false;
  k.select_block = 0;  // every pixel of the level
  k.debug_output = true;
  return k;
}

namespace {

// The pass with the default kernel options, registered before main() so that exported kernel
// binaries hold it: the tracker measures every frame's texture residual with it (the honest-status
// check, texture_residual.h), and the calibration tracks its drives.
const bool kDefaultVariantRegistered = [] {
  ocl::Runtime::register_build_options("texture_residual", "", {tasks::kTrack, tasks::kCalibrate});
  ocl::Runtime::register_build_options(
      "warp_reduce", WarpReduce::build_options(kMotionParams, ResidualImager::kernel_options(WarpReduceOptions())),
      {tasks::kTrack, tasks::kCalibrate});
  return true;
}();

}  // namespace

ResidualImager::ResidualImager(ocl::Runtime& runtime, const Eigen::Matrix3d& K, const WarpReduceOptions& kernel)
    : runtime_(runtime), K_(K), pass_(runtime, kMotionParams, kernel_options(kernel)),
      texture_kernel_(runtime.program("texture_residual", ""), "texture_residual") {}

ResidualImager::~ResidualImager() = default;

WarpInputs ResidualImager::run_pass(const AlignmentRecord& a, const Extrinsics& extrinsics, int level,
                                    ReduceSums* sums) {
  const int levels = std::min(a.reference.num_levels(), a.live.num_levels());
  if (level < 0 || level >= levels)
    throw_invalid_argument("residual image: level " + std::to_string(level) + " is not one of the pyramid's 0.." +
                           std::to_string(levels - 1));
  const PyramidLevel& R = a.reference.levels[static_cast<size_t>(level)];
  const PyramidLevel& L = a.live.levels[static_cast<size_t>(level)];
  if (L.width < 2 || L.height < 2)
    throw_invalid_argument("residual image: level " + std::to_string(level) + " is smaller than 2 x 2 pixels");

  // The final alignment's warp at this level; the generators only feed the sums, unused here.
  const Eigen::Matrix3d Kl = level_camera_matrix(K_, level);
  const MotionHomography mh = motion_homography(Kl, extrinsics, a.motion);
  WarpInputs in;
  in.H = a.reference_attitude.zero() && a.live_attitude.zero()
             ? mh.H
             : ground_homography(Kl, on_plane(extrinsics, a.reference_attitude),
                                 on_plane(extrinsics, a.live_attitude), a.motion.matrix3d());
  in.nparam = kMotionParams;
  for (size_t i = 0; i < static_cast<size_t>(kMotionParams); ++i) in.G[i] = mh.G[i];
  in.gain = std::exp(a.log_gain);
  in.bias = a.bias;
  in.huber_k = a.huber_k;

  const size_t n = static_cast<size_t>(R.width) * static_cast<size_t>(R.height);
  if (n > debug_capacity_) {
    debug_ = cl::Buffer(runtime_.context(), CL_MEM_READ_WRITE, n * 4 * sizeof(float));
    debug_capacity_ = n;
  }
  pass_.run(R.data, R.width, R.height, L.data, L.width, L.height, in, sums, &debug_);
  return in;
}

double ResidualImager::texture_residual(const AlignmentRecord& a, const Extrinsics& extrinsics, int level) {
  ReduceSums sums;
  run_pass(a, extrinsics, level, &sums);
  const PyramidLevel& R = a.reference.levels[static_cast<size_t>(level)];
  constexpr size_t kWx = 16, kWy = 4;  // texture_residual.cl's TR_WG_X, TR_WG_Y
  const size_t gx = (static_cast<size_t>(R.width) + kWx - 1) / kWx, gy = (static_cast<size_t>(R.height) + kWy - 1) / kWy;
  const size_t floats = 3 * gx * gy;
  if (floats > texture_capacity_) {
    texture_partials_ = cl::Buffer(runtime_.context(), CL_MEM_WRITE_ONLY, floats * sizeof(float));
    texture_capacity_ = floats;
    host_texture_.resize(floats);
  }
  texture_kernel_.setArg(0, debug_);
  texture_kernel_.setArg(1, R.data);
  texture_kernel_.setArg(2, R.width);
  texture_kernel_.setArg(3, R.height);
  texture_kernel_.setArg(4, texture_partials_);
  cl::CommandQueue& q = runtime_.queue();
  q.enqueueNDRangeKernel(texture_kernel_, cl::NullRange, cl::NDRange(gx * kWx, gy * kWy), cl::NDRange(kWx, kWy));
  q.enqueueReadBuffer(texture_partials_, CL_TRUE, 0, floats * sizeof(float), host_texture_.data());
  double sr = 0.0, si = 0.0, count = 0.0;
  for (size_t g = 0; g < gx * gy; ++g) {
    sr += static_cast<double>(host_texture_[3 * g]);
    si += static_cast<double>(host_texture_[3 * g + 1]);
    count += static_cast<double>(host_texture_[3 * g + 2]);
  }
  return texture_residual_ratio(sr, si, count);
}

void ResidualImager::compute(const AlignmentRecord& a, const Extrinsics& extrinsics, int level, ResidualImage* out) {
  ReduceSums sums;
  const WarpInputs in = run_pass(a, extrinsics, level, &sums);
  const PyramidLevel& R = a.reference.levels[static_cast<size_t>(level)];
  const size_t n = static_cast<size_t>(R.width) * static_cast<size_t>(R.height);
  host_debug_.resize(4 * n);
  host_ref_.resize(4 * n);
  cl::CommandQueue& q = runtime_.queue();
  q.enqueueReadBuffer(debug_, CL_FALSE, 0, n * 4 * sizeof(float), host_debug_.data());
  q.enqueueReadBuffer(R.data, CL_TRUE, 0, n * 4 * sizeof(float), host_ref_.data());

  out->level = level;
  out->width = R.width;
  out->height = R.height;
  out->residual.resize(n);
  out->weight.resize(n);
  out->intensity.resize(n);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < n; ++i) {
    // (r, weight, valid, rho): r and the weight are already 0 where the pair is not valid.
    out->residual[i] = host_debug_[4 * i];
    out->weight[i] = host_debug_[4 * i + 1];
    out->intensity[i] = host_ref_[4 * i + 3] != 0.0f ? host_ref_[4 * i] : nan;
  }
  out->H = in.H;
  out->gain = in.gain;
  out->bias = in.bias;
  out->huber_k = in.huber_k;
  out->tracked_level = a.finest_level;
  out->valid = sums.valid;
  out->inliers = sums.inlier;
}

}  // namespace planarvo::track
