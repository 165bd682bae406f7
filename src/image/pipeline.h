// The per-frame image pipeline: an 8-bit grey camera frame in, the device pyramid of pyramid.h
// out (upload -> undistortion -> prefilter -> Gaussian pyramid -> gradients, all on the OpenCL
// device), plus the plain C++ reference of every stage, and helpers that move pyramids between
// host and device (for tests, and for the tracker's tests). See README.md, "The image pipeline".
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <CL/opencl.hpp>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "image/photometric.h"
#include "image/pyramid.h"
#include "image/rolling_shutter.h"
#include "image/undistort.h"

namespace planarvo {

namespace ocl {
class Runtime;
}

// ---------------------------------------------------------------------------------------------
// The pipeline's definition, as plain C++ (the references the kernels are tested against).
//
// Between stages a level is an "intensity image": CV_32FC1, grey levels 0..255, with
// kInvalidIntensity where the pixel is not valid. The kernels use the same encoding in their
// intermediate buffers: -2^20 is so far below any sum of valid terms (at most 1024 x 255) that a
// weighted sum with one invalid term of weight >= 1 is negative, so the kernels read validity
// from a sum's sign. The references test every term instead.
inline constexpr float kInvalidIntensity = -1048576.0f;

// Stage 1, undistortion: gray (CV_8UC1, the map's size) sampled bilinearly at the map's
// coordinates (exactly remap_bilinear), kInvalidIntensity where the map is not valid.
cv::Mat undistort_reference(const cv::Mat& gray, const UndistortMap& map);

// Stage 1b, the prefilter (ImagePipelineOptions::prefilter): an intensity image -> the same
// size, the separable [1 2 1] / 4 binomial in x then y (a Gaussian of sigma about 0.7 px), taps
// clamped to the edge, invalid if any tap is. Float arithmetic in the kernel's order: each
// row's (l + r) + 2c, then (top + bottom) + 2 centre, / 16.
cv::Mat smooth_reference(const cv::Mat& level);

// Stage 2, one pyramid step: level l (an intensity image) -> level l + 1 of
// ceil(w / 2) x ceil(h / 2) pixels. Output pixel (u, v) is the 5-tap Gaussian [1 4 6 4 1] / 16
// (separable) of level l sampled at its centre, level-l (2u + 0.5, 2v + 0.5), i.e. the mean of
// the blurred pixels 2u, 2u + 1 (x) and 2v, 2v + 1 (y). Together that is the separable 6-tap
// binomial [1 5 10 10 5 1] / 32 over level-l columns 2u - 2 .. 2u + 3 and rows 2v - 2 .. 2v + 3,
// symmetric about the centre, so the level's geometry is exactly pyramid.h's. Taps outside the
// image are clamped to the edge; an invalid tap makes the output invalid. Float arithmetic in
// the kernel's order: each row's horizontal sum, then the weighted sum of the six rows, / 1024.
cv::Mat downsample_reference(const cv::Mat& level);

// Stage 3, gradients: an intensity image -> the level's CV_32FC4 image in pyramid.h's layout:
// (I, (I(u+1) - I(u-1)) * 0.5, (I(v+1) - I(v-1)) * 0.5, 1), or all zeros where the pixel or
// one of its four neighbours is invalid or outside the image.
cv::Mat gradient_reference(const cv::Mat& level);

// The whole pipeline: one CV_32FC4 image per level, levels[0] at full resolution; with
// prefilter, level 0's intensity is smoothed before the pyramid is built from it.
std::vector<cv::Mat> pipeline_reference(const cv::Mat& gray, const UndistortMap& map, int levels,
                                        bool prefilter = true);

// ---------------------------------------------------------------------------------------------
// Pyramids between host and device.

inline constexpr int kMaxPyramidLevels = 16;

// Device buffers for a pyramid of a width x height image with the given number of levels
// (level sizes of pyramid.h), contents undefined. Throws InvalidArgument for sizes < 1 or
// levels outside 1..kMaxPyramidLevels.
Pyramid allocate_pyramid(ocl::Runtime& runtime, int width, int height, int levels);

// Uploads host levels (CV_32FC4 each, level l + 1 of size ceil(level l / 2)) into a new device
// pyramid; throws InvalidArgument otherwise. Blocks until the data is on the device.
Pyramid upload_pyramid(ocl::Runtime& runtime, const std::vector<cv::Mat>& levels);

// Reads a device pyramid back: one CV_32FC4 image per level. Blocks (after everything enqueued
// before it on the runtime's queue).
std::vector<cv::Mat> download_pyramid(ocl::Runtime& runtime, const Pyramid& pyramid);

// ---------------------------------------------------------------------------------------------
// The OpenCL pipeline.

struct ImagePipelineOptions {
  // Work-group shapes, passed to the kernels as -D build options (0: the kernels' defaults,
  // 16 x 4). x is along image rows, where each work-item makes 8 consecutive pixels.
  int undistort_wg_x = 0, undistort_wg_y = 0;
  int pyramid_wg_x = 0, pyramid_wg_y = 0;
  // Build with -cl-fast-relaxed-math (off: it measured no faster on PoCL; see README.md).
  bool fast_math = false;
  // Smooth level 0 (smooth_reference) before the pyramid is built from it: pixel noise,
  // resampled bilinearly by the alignment, otherwise biases it (src/track/README.md, "The
  // prefilter").
  bool prefilter = true;
  // Under a photometric model that is not the identity (settled, or a known flat field), the
  // noise's share in each level's gradients is taken out (gradient_noise.h): corrected, the noise
  // varies over the image and otherwise pulls the alignment towards zero motion.
  bool decorrelate_noise = true;
  // The photometric model (photometric.h): between the undistortion and the prefilter, the
  // light fixed to the camera is taken out and saturated pixels left out; learnt from the
  // frames process() is told are in motion. Off by default here (the tracker turns it on).
  PhotometricOptions photometric{false};
};

// Host wall time of each stage when the queue is drained after each (ImagePipeline::
// process_timed); milliseconds.
struct PipelineTimings {
  double upload_ms = 0;     // the frame into the device buffer
  double undistort_ms = 0;  // remap into level 0's intensity image (and the prefilter)
  double pyramid_ms = 0;    // the Gaussian steps: levels 1..n-1 intensity images
  double gradient_ms = 0;   // gradients and the float4 layout of every level
  double total_ms() const { return upload_ms + undistort_ms + pyramid_ms + gradient_ms; }
};

// The pipeline's kernels with their launch shapes: what ImagePipeline enqueues, one call per
// kernel, on the runtime's queue and without waiting. Tests run each stage on buffers of their
// own through it. Buffers hold what the kernels in kernels/image/undistort.cl and kernels/image/pyramid.cl
// describe: intensity images are width * height floats (kInvalidIntensity where not valid).
class PipelineKernels {
 public:
  // Registers the build options and builds (or loads) the two programs.
  PipelineKernels(ocl::Runtime& runtime, const ImagePipelineOptions& options = {});

  // The undistortion map as the kernel reads it, computed from an UndistortMap in
  // remap_bilinear's float arithmetic: per pixel the index y0 * width + x0 of the top-left
  // source pixel (-1 where not valid) and the weights (ax, ay) of its right and lower
  // neighbours, interleaved; each padded by 8 pixels (index -1).
  struct DeviceMap {
    std::vector<cl_int> index;   // width * height + 8
    std::vector<float> weights;  // 2 * (width * height + 8)
  };
  static DeviceMap device_map(const UndistortMap& map);
  // The bytes the kernel may read from the frame buffer: the frame, then width + 1 more (the
  // right/lower neighbours of samples on the last column/row, read with weight 0).
  static size_t frame_buffer_size(int width, int height);

  // frame: frame_buffer_size() bytes; index, weights: device_map()'s; dst: the level-0
  // intensity image.
  void undistort(const cl::Buffer& frame, const cl::Buffer& index, const cl::Buffer& weights,
                 int width, int height, const cl::Buffer& dst);
  // The rolling-shutter undistortion (rolling_shutter.h): frame as undistort's; map: width *
  // height float2, the UndistortMap's (map_x, map_y) interleaved, then 8 pairs outside any image
  // (-1e6); grid: RowWarp::delta of a warp of this size (the light field may follow it); roi:
  // the region of interest's (min x, min y, max x, max y).
  void undistort_rolling(const cl::Buffer& frame, const cl::Buffer& map, const cl::Buffer& grid,
                         const RowWarp& warp, const cl_float4& roi, const cl::Buffer& dst);
  // The photometric correction: raw -> dst (intensity images of width x height, not the same
  // buffer), model PhotometricModel's planes.
  void photometric(const cl::Buffer& raw, const cl::Buffer& model, float saturation, int width,
                   int height, const cl::Buffer& dst);
  // The photometric correction of undistort_rolling's output (kernel `photometric_rolling`):
  // grid: the warp's buffer, RowWarp::delta then RowWarp::light.
  void photometric_rolling(const cl::Buffer& raw, const cl::Buffer& model, const cl::Buffer& grid,
                           const RowWarp& warp, float saturation, const cl::Buffer& dst);
  // The photometric statistics' update from raw (PhotometricModel's planes) with weight alpha.
  void photometric_learn(const cl::Buffer& raw, const cl::Buffer& stats, float alpha, int width,
                         int height);
  // src, dst: intensity images of width x height (not the same buffer).
  void smooth(const cl::Buffer& src, int width, int height, const cl::Buffer& dst);
  // src: an intensity image of src_width x src_height; dst: the next level's
  // (level_size(src_width, 1) x level_size(src_height, 1)).
  void downsample(const cl::Buffer& src, int src_width, int src_height, const cl::Buffer& dst);
  // src: an intensity image; dst: width * height float4, pyramid.h's layout.
  void gradient(const cl::Buffer& src, int width, int height, const cl::Buffer& dst);
  // As gradient, less beta (I - mean) (gradient_noise.h): beta, width * height float2.
  void gradient_decorrelated(const cl::Buffer& src, int width, int height, const cl::Buffer& beta, float mean,
                             const cl::Buffer& dst);

 private:
  ocl::Runtime& runtime_;
  cl::Kernel undistort_, undistort_rolling_, photometric_, photometric_learn_, photometric_rolling_, smooth_, downsample_, gradient_,
      gradient_decorrelated_;
  size_t undistort_wg_[2] = {1, 1}, pyramid_wg_[2] = {1, 1};
};

class ImagePipeline {
 public:
  // Computes and uploads the undistortion map of the camera, builds the kernels and allocates
  // the intermediate buffers. Throws InvalidArgument for a camera that does not validate or
  // levels outside 1..kMaxPyramidLevels, Error(OpenCL) when a build or an allocation fails.
  ImagePipeline(ocl::Runtime& runtime, const CameraModel& camera, int levels,
                const ImagePipelineOptions& options = {});
  ~ImagePipeline();
  ImagePipeline(const ImagePipeline&) = delete;
  ImagePipeline& operator=(const ImagePipeline&) = delete;

  int width() const;
  int height() const;
  int levels() const;
  const CameraModel& camera() const;
  const UndistortMap& map() const;

  // Processes one frame (width x height bytes, rows `stride` bytes apart) into `out`. `out`'s
  // buffers are allocated on the first call (or when its levels do not match this pipeline)
  // and reused afterwards. The frame is copied before process() returns (the caller may reuse
  // its memory); the kernels are enqueued on the runtime's in-order queue and not waited for,
  // so whatever is enqueued next (the tracker) sees the finished pyramid.
  // Throws InvalidArgument naming both sizes when the frame is not the camera's size, or when
  // gray is null or stride < width; Error(OpenCL) when an OpenCL call fails.
  void process(const uint8_t* gray, int width, int height, size_t stride, Pyramid& out);
  // The same for a CV_8UC1 image (any other type is InvalidArgument).
  void process(const cv::Mat& gray, Pyramid& out);
  // The photometric model learns from the last frame processed (its caller knows the frame is
  // in motion relative to the last one learnt from). Nothing when the model is off or not
  // learning.
  void learn();
  // The last frame again (already on the device) into `out`, with the photometric model as it
  // is now and without learning from it: after PhotometricModel::refit, so that a keyframe and
  // the frames aligned with it are corrected alike. InvalidArgument before any frame.
  void reprocess(Pyramid& out);
  // Keeps the last frame on the device (a copy), for reprocess_kept: a tracker keeps its
  // keyframe's, so that a new photometric model can correct the keyframe again at any frame.
  void keep();
  // The kept frame into `out`, as reprocess() does the last one. It leaves the photometric
  // learning's frame (learn()) to the kept one until the next process or reprocess.
  // InvalidArgument when nothing was kept.
  void reprocess_kept(Pyramid& out);
  // The rolling shutter (rolling_shutter.h): the row warp with which the last frame (and the
  // frames processed after it until the next call) is undistorted, to the global-shutter image at
  // its stamp. The identity (the default) is the plain undistortion, bit for bit. Its caller
  // knows the robot's velocity (rolling_shutter_warp); after a better estimate, set it again and
  // reprocess(). InvalidArgument when its height is not the camera's.
  void set_row_warp(const RowWarp& warp);
  // The same for the kept frame (reprocess_kept); keep() keeps the last frame's with it.
  void set_kept_row_warp(const RowWarp& warp);
  // The photometric model, or null when it is off.
  PhotometricModel* photometric();

  // process(), draining the queue before and after each stage to time it (benchmarks only).
  PipelineTimings process_timed(const cv::Mat& gray, Pyramid& out);

  // The build options of the two programs ("undistort", "pyramid") for the given options, as
  // registered with ocl::Runtime::register_build_options (the defaults' before main()).
  static std::string undistort_build_options(const ImagePipelineOptions& options = {});
  static std::string pyramid_build_options(const ImagePipelineOptions& options = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace planarvo
