// The OpenCL image pipeline (pipeline.h): buffers, kernels and their launch order, and pyramids
// between host and device.
#include "image/pipeline.h"

#include <chrono>
#include <string>

#include "core/error.h"
#include "image/gradient_noise.h"
#include "ocl/runtime.h"

namespace planarvo {
namespace {

// Each work-item of the kernels makes this many consecutive pixels of a row.
constexpr size_t kPixelsPerItem = 8;

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

[[noreturn]] void throw_opencl(const std::string& what, const cl::Error& e) {
  throw Error(ErrorCode::OpenCL, "image pipeline: " + what + " failed: " + e.what() + " " +
                                     ocl::error_name(e.err()));
}

size_t round_up(size_t n, size_t m) { return (n + m - 1) / m * m; }

std::string wg_options(const char* prefix, int x, int y) {
  std::string s;
  if (x > 0) s += std::string("-D ") + prefix + "_WG_X=" + std::to_string(x) + " ";
  if (y > 0) s += std::string("-D ") + prefix + "_WG_Y=" + std::to_string(y) + " ";
  return s;
}

void check_levels(int levels, const char* what) {
  if (levels < 1 || levels > kMaxPyramidLevels)
    throw_invalid_argument(std::string(what) + ": levels must be 1.." +
                           std::to_string(kMaxPyramidLevels) + ", not " + std::to_string(levels));
}

// Enqueues k over a width x height image: kPixelsPerItem pixels per work-item along x, global
// sizes rounded up to the work-group (the kernels bounds-check).
void launch(cl::CommandQueue& q, const cl::Kernel& k, const size_t wg[2], int width, int height) {
  const size_t items = (static_cast<size_t>(width) + kPixelsPerItem - 1) / kPixelsPerItem;
  q.enqueueNDRangeKernel(k, cl::NullRange,
                         cl::NDRange(round_up(items, wg[0]), round_up(static_cast<size_t>(height), wg[1])),
                         cl::NDRange(wg[0], wg[1]));
}

cl::Kernel make_kernel(cl::Program& program, const char* name, cl::Device& device, size_t wg[2]) {
  cl::Kernel k(program, name);
  // Launch with the compiled reqd_work_group_size, so other -D values need no host change.
  const auto compiled = k.getWorkGroupInfo<CL_KERNEL_COMPILE_WORK_GROUP_SIZE>(device);
  wg[0] = compiled[0];
  wg[1] = compiled[1];
  return k;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

// ---------------------------------------------------------------------------------------------

Pyramid allocate_pyramid(ocl::Runtime& runtime, int width, int height, int levels) {
  check_levels(levels, "allocate_pyramid");
  if (width < 1 || height < 1)
    throw_invalid_argument("allocate_pyramid: the image size " + size_text(width, height) +
                           " is not positive");
  Pyramid p;
  try {
    for (int l = 0; l < levels; ++l) {
      PyramidLevel level;
      level.width = level_size(width, l);
      level.height = level_size(height, l);
      level.data = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE,
                              static_cast<size_t>(level.width) * static_cast<size_t>(level.height) *
                                  4 * sizeof(float));
      p.levels.push_back(std::move(level));
    }
  } catch (const cl::Error& e) {
    throw_opencl("allocating a pyramid of " + size_text(width, height), e);
  }
  return p;
}

Pyramid upload_pyramid(ocl::Runtime& runtime, const std::vector<cv::Mat>& levels) {
  if (levels.empty() || levels.size() > static_cast<size_t>(kMaxPyramidLevels))
    throw_invalid_argument("upload_pyramid: expected 1.." + std::to_string(kMaxPyramidLevels) +
                           " levels, got " + std::to_string(levels.size()));
  for (size_t l = 0; l < levels.size(); ++l) {
    if (levels[l].type() != CV_32FC4 || levels[l].empty())
      throw_invalid_argument("upload_pyramid: level " + std::to_string(l) +
                             " is not a non-empty CV_32FC4 image");
    const int w = level_size(levels[0].cols, static_cast<int>(l));
    const int h = level_size(levels[0].rows, static_cast<int>(l));
    if (levels[l].cols != w || levels[l].rows != h)
      throw_invalid_argument("upload_pyramid: level " + std::to_string(l) + " is " +
                             size_text(levels[l].cols, levels[l].rows) + ", expected " +
                             size_text(w, h) + " (pyramid.h's level_size)");
  }
  Pyramid p = allocate_pyramid(runtime, levels[0].cols, levels[0].rows,
                               static_cast<int>(levels.size()));
  try {
    for (size_t l = 0; l < levels.size(); ++l) {
      const cv::Mat m = levels[l].isContinuous() ? levels[l] : levels[l].clone();
      runtime.queue().enqueueWriteBuffer(p.levels[l].data, CL_TRUE, 0, m.total() * m.elemSize(),
                                         m.ptr());
    }
  } catch (const cl::Error& e) {
    throw_opencl("uploading a pyramid", e);
  }
  return p;
}

std::vector<cv::Mat> download_pyramid(ocl::Runtime& runtime, const Pyramid& pyramid) {
  std::vector<cv::Mat> out;
  try {
    for (const PyramidLevel& level : pyramid.levels) {
      cv::Mat m(level.height, level.width, CV_32FC4);
      runtime.queue().enqueueReadBuffer(level.data, CL_TRUE, 0, m.total() * m.elemSize(), m.ptr());
      out.push_back(m);
    }
  } catch (const cl::Error& e) {
    throw_opencl("downloading a pyramid", e);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------

std::string ImagePipeline::undistort_build_options(const ImagePipelineOptions& o) {
  return ocl::normalize_build_options(wg_options("UNDISTORT", o.undistort_wg_x, o.undistort_wg_y) +
                                      (o.fast_math ? "-cl-fast-relaxed-math" : ""));
}

std::string ImagePipeline::pyramid_build_options(const ImagePipelineOptions& o) {
  return ocl::normalize_build_options(wg_options("PYRAMID", o.pyramid_wg_x, o.pyramid_wg_y) +
                                      (o.fast_math ? "-cl-fast-relaxed-math" : ""));
}

PipelineKernels::PipelineKernels(ocl::Runtime& runtime, const ImagePipelineOptions& options)
    : runtime_(runtime) {
  const std::string undistort_opts = ImagePipeline::undistort_build_options(options);
  const std::string pyramid_opts = ImagePipeline::pyramid_build_options(options);
  ocl::Runtime::register_build_options("undistort", undistort_opts);
  ocl::Runtime::register_build_options("pyramid", pyramid_opts);
  try {
    cl::Device& dev = runtime.device();
    cl::Program& undistort = runtime.program("undistort", undistort_opts);
    undistort_ = make_kernel(undistort, "undistort", dev, undistort_wg_);
    undistort_rolling_ = make_kernel(undistort, "undistort_rolling", dev, undistort_wg_);
    photometric_ = make_kernel(undistort, "photometric", dev, undistort_wg_);
    photometric_learn_ = make_kernel(undistort, "photometric_learn", dev, undistort_wg_);
    photometric_rolling_ = make_kernel(undistort, "photometric_rolling", dev, undistort_wg_);
    cl::Program& pyramid = runtime.program("pyramid", pyramid_opts);
    smooth_ = make_kernel(pyramid, "smooth", dev, pyramid_wg_);
    downsample_ = make_kernel(pyramid, "downsample", dev, pyramid_wg_);
    gradient_ = make_kernel(pyramid, "gradient", dev, pyramid_wg_);
    gradient_decorrelated_ = make_kernel(pyramid, "gradient_decorrelated", dev, pyramid_wg_);
  } catch (const cl::Error& e) {
    throw_opencl("creating the kernels", e);
  }
}

PipelineKernels::DeviceMap PipelineKernels::device_map(const UndistortMap& map) {
  const size_t n = static_cast<size_t>(map.width) * static_cast<size_t>(map.height);
  DeviceMap d;
  d.index.assign(n + kPixelsPerItem, -1);
  d.weights.assign(2 * (n + kPixelsPerItem), 0.0f);
  for (size_t i = 0; i < n; ++i) {
    if (!map.valid[i]) continue;
    // remap_bilinear's arithmetic: valid coordinates are >= 0, so truncation is floor.
    const float sx = map.map_x[i], sy = map.map_y[i];
    const int x0 = static_cast<int>(sx), y0 = static_cast<int>(sy);
    d.index[i] = y0 * map.width + x0;
    d.weights[2 * i] = sx - static_cast<float>(x0);
    d.weights[2 * i + 1] = sy - static_cast<float>(y0);
  }
  return d;
}

size_t PipelineKernels::frame_buffer_size(int width, int height) {
  return static_cast<size_t>(width) * static_cast<size_t>(height) + static_cast<size_t>(width) + 1;
}

void PipelineKernels::undistort(const cl::Buffer& frame, const cl::Buffer& index,
                                const cl::Buffer& weights, int width, int height,
                                const cl::Buffer& dst) {
  undistort_.setArg(0, frame);
  undistort_.setArg(1, index);
  undistort_.setArg(2, weights);
  undistort_.setArg(3, static_cast<cl_int>(width));
  undistort_.setArg(4, static_cast<cl_int>(height));
  undistort_.setArg(5, dst);
  launch(runtime_.queue(), undistort_, undistort_wg_, width, height);
}

void PipelineKernels::undistort_rolling(const cl::Buffer& frame, const cl::Buffer& map, const cl::Buffer& grid,
                                        const RowWarp& warp, const cl_float4& roi, const cl::Buffer& dst) {
  undistort_rolling_.setArg(0, frame);
  undistort_rolling_.setArg(1, map);
  undistort_rolling_.setArg(2, grid);
  undistort_rolling_.setArg(3, static_cast<cl_int>(warp.nodes_x));
  undistort_rolling_.setArg(4, static_cast<cl_int>(warp.nodes_y));
  undistort_rolling_.setArg(5, 1.0f / static_cast<float>(warp.step));
  undistort_rolling_.setArg(6, static_cast<cl_int>(warp.width));
  undistort_rolling_.setArg(7, static_cast<cl_int>(warp.height));
  undistort_rolling_.setArg(8, roi);
  undistort_rolling_.setArg(9, dst);
  launch(runtime_.queue(), undistort_rolling_, undistort_wg_, warp.width, warp.height);
}

void PipelineKernels::downsample(const cl::Buffer& src, int src_width, int src_height,
                                 const cl::Buffer& dst) {
  const int dw = level_size(src_width, 1), dh = level_size(src_height, 1);
  downsample_.setArg(0, src);
  downsample_.setArg(1, static_cast<cl_int>(src_width));
  downsample_.setArg(2, static_cast<cl_int>(src_height));
  downsample_.setArg(3, dst);
  downsample_.setArg(4, static_cast<cl_int>(dw));
  downsample_.setArg(5, static_cast<cl_int>(dh));
  launch(runtime_.queue(), downsample_, pyramid_wg_, dw, dh);
}

void PipelineKernels::photometric(const cl::Buffer& raw, const cl::Buffer& model, float saturation,
                                  int width, int height, const cl::Buffer& dst) {
  photometric_.setArg(0, raw);
  photometric_.setArg(1, model);
  photometric_.setArg(2, saturation);
  photometric_.setArg(3, static_cast<cl_int>(width));
  photometric_.setArg(4, static_cast<cl_int>(height));
  photometric_.setArg(5, dst);
  launch(runtime_.queue(), photometric_, undistort_wg_, width, height);
}

void PipelineKernels::photometric_rolling(const cl::Buffer& raw, const cl::Buffer& model, const cl::Buffer& grid,
                                          const RowWarp& warp, float saturation, const cl::Buffer& dst) {
  photometric_rolling_.setArg(0, raw);
  photometric_rolling_.setArg(1, model);
  photometric_rolling_.setArg(2, grid);
  photometric_rolling_.setArg(3, static_cast<cl_int>(warp.nodes_x));
  photometric_rolling_.setArg(4, static_cast<cl_int>(warp.nodes_y));
  photometric_rolling_.setArg(5, 1.0f / static_cast<float>(warp.step));
  photometric_rolling_.setArg(6, saturation);
  photometric_rolling_.setArg(7, static_cast<cl_int>(warp.width));
  photometric_rolling_.setArg(8, static_cast<cl_int>(warp.height));
  photometric_rolling_.setArg(9, dst);
  launch(runtime_.queue(), photometric_rolling_, undistort_wg_, warp.width, warp.height);
}

void PipelineKernels::photometric_learn(const cl::Buffer& raw, const cl::Buffer& stats, float alpha,
                                        int width, int height) {
  photometric_learn_.setArg(0, raw);
  photometric_learn_.setArg(1, stats);
  photometric_learn_.setArg(2, alpha);
  photometric_learn_.setArg(3, static_cast<cl_int>(width));
  photometric_learn_.setArg(4, static_cast<cl_int>(height));
  launch(runtime_.queue(), photometric_learn_, undistort_wg_, width, height);
}

void PipelineKernels::smooth(const cl::Buffer& src, int width, int height, const cl::Buffer& dst) {
  smooth_.setArg(0, src);
  smooth_.setArg(1, static_cast<cl_int>(width));
  smooth_.setArg(2, static_cast<cl_int>(height));
  smooth_.setArg(3, dst);
  launch(runtime_.queue(), smooth_, pyramid_wg_, width, height);
}

void PipelineKernels::gradient(const cl::Buffer& src, int width, int height, const cl::Buffer& dst) {
  gradient_.setArg(0, src);
  gradient_.setArg(1, static_cast<cl_int>(width));
  gradient_.setArg(2, static_cast<cl_int>(height));
  gradient_.setArg(3, dst);
  launch(runtime_.queue(), gradient_, pyramid_wg_, width, height);
}

void PipelineKernels::gradient_decorrelated(const cl::Buffer& src, int width, int height, const cl::Buffer& beta,
                                            float mean, const cl::Buffer& dst) {
  gradient_decorrelated_.setArg(0, src);
  gradient_decorrelated_.setArg(1, static_cast<cl_int>(width));
  gradient_decorrelated_.setArg(2, static_cast<cl_int>(height));
  gradient_decorrelated_.setArg(3, dst);
  gradient_decorrelated_.setArg(4, beta);
  gradient_decorrelated_.setArg(5, mean);
  launch(runtime_.queue(), gradient_decorrelated_, pyramid_wg_, width, height);
}

// ---------------------------------------------------------------------------------------------

struct ImagePipeline::Impl {
  ocl::Runtime& rt;
  CameraModel camera;
  UndistortMap map;
  int levels = 0;
  PipelineKernels kernels;
  cl::Buffer frame;                   // PipelineKernels::frame_buffer_size bytes
  cl::Buffer map_index, map_weights;  // PipelineKernels::device_map
  std::vector<cl::Buffer> intensity;  // per level, its intensity image
  bool prefilter = true;
  bool decorrelate_noise = true;
  cl::Buffer raw;                     // level 0 before the prefilter (when it is on)
  std::unique_ptr<PhotometricModel> photometric;  // when on
  cl::Buffer uncorrected;             // level 0 before the photometric correction (when on)
  bool has_frame = false;             // a frame is in `frame` (reprocess)
  cl::Buffer kept;                    // a copy of `frame` (keep, reprocess_kept)
  bool has_kept = false;
  // The rolling shutter: the map as (x, y) pairs (made on the first row warp that is not the
  // identity), and the current and the kept frame's row warps (a buffer each, when not identity:
  // RowWarp::delta, then RowWarp::light).
  cl::Buffer map_xy;
  cl_float4 roi{};
  struct Rows {
    RowWarp warp;
    cl::Buffer buffer;
    bool identity = true;
  } row_warp, kept_row_warp;
  // The noise's share in the gradients under the photometric model (gradient_noise.h): beta per
  // level, made from the model of revision beta_revision (-1: none yet).
  std::vector<cl::Buffer> beta;
  long beta_revision = -1;
  // The corrected image's mean level, which beta multiplies the intensity's difference from
  // (any level not made from the pixel's own noise serves; near the image's, the texture's share
  // stays small): raw x scale over every 8th pixel of every 8th row of the last frame processed
  // (the raw pixel at the undistorted one's coordinates: a mean needs no more).
  float corrected_mean = 0.0f;
  // Whether the gradients take the noise's share out: an evenly lit camera (the identity model)
  // has the same noise everywhere, nothing to take out; a young model (fitted from fewer than
  // kPhotometricSettledFrames frames) is the statistics' noise as much as the light, and its
  // log's slope more so.
  bool decorrelating() const {
    if (!decorrelate_noise || !photometric) return false;
    const PhotometricFit& fit = photometric->fit();
    return !fit.identity && (fit.frames == 0 || fit.frames >= kPhotometricSettledFrames);
  }
  // Noted for a young model too: a refit that settles it is followed by reprocess(), which has no
  // frame of its own to note.
  void note_mean(const uint8_t* gray, size_t stride) {
    if (!decorrelate_noise || !photometric || photometric->fit().identity) return;
    const cv::Mat& scale = photometric->fit().scale;
    const double white = photometric->options().saturation;
    double sum = 0.0;
    long n = 0;
    for (int y = 4; y < camera.height; y += 8)
      for (int x = 4; x < camera.width; x += 8) {
        const float sc = scale.at<float>(y, x);
        const double v = gray[static_cast<size_t>(y) * stride + static_cast<size_t>(x)];
        if (sc > 0.0f && v < white) {
          sum += v * sc;
          ++n;
        }
      }
    if (n > 0) corrected_mean = static_cast<float>(sum / static_cast<double>(n));
  }
  // What `uncorrected` was last made from (learn()).
  const cl::Buffer* undistorted_source = nullptr;
  bool undistorted_rolling = false;
  Impl(ocl::Runtime& r, const ImagePipelineOptions& o) : rt(r), kernels(r, o), prefilter(o.prefilter), decorrelate_noise(o.decorrelate_noise) {}

  int w(int l) const { return level_size(camera.width, l); }
  int h(int l) const { return level_size(camera.height, l); }

  void ensure(Pyramid& out) const {
    bool ok = out.num_levels() == levels;
    for (int l = 0; ok && l < levels; ++l) {
      const PyramidLevel& level = out.levels[static_cast<size_t>(l)];
      ok = level.width == w(l) && level.height == h(l) && level.data() != nullptr;
    }
    if (!ok) out = allocate_pyramid(rt, camera.width, camera.height, levels);
  }

  void check_frame(const uint8_t* gray, int fw, int fh, size_t stride) const {
    if (fw != camera.width || fh != camera.height)
      throw_invalid_argument("image pipeline: the frame is " + size_text(fw, fh) +
                             ", the camera's images are " + size_text(camera.width, camera.height));
    if (!gray) throw_invalid_argument("image pipeline: the frame is null");
    if (stride < static_cast<size_t>(fw))
      throw_invalid_argument("image pipeline: the frame's stride " + std::to_string(stride) +
                             " is less than its width " + std::to_string(fw));
  }

  void upload(const uint8_t* gray, size_t stride) {
    // Blocking, so the caller may reuse its frame as soon as process() returns.
    const size_t row = static_cast<size_t>(camera.width), rows = static_cast<size_t>(camera.height);
    if (stride == row) {
      rt.queue().enqueueWriteBuffer(frame, CL_TRUE, 0, row * rows, gray);
    } else {
      const cl::array<cl::size_type, 3> origin{0, 0, 0};
      const cl::array<cl::size_type, 3> region{row, rows, 1};
      rt.queue().enqueueWriteBufferRect(frame, CL_TRUE, origin, origin, region, row, 0, stride, 0,
                                        gray);
    }
  }

  void set_rows(Rows& r, const RowWarp& warp) {
    if (warp.width != camera.width || warp.height != camera.height || warp.nodes_x < 2 || warp.nodes_y < 2 ||
        warp.step < 8 ||
        warp.delta.size() != 2 * static_cast<size_t>(warp.nodes_x) * static_cast<size_t>(warp.nodes_y) ||
        warp.light.size() != warp.delta.size())
      throw_invalid_argument("image pipeline: the row warp is for " + size_text(warp.width, warp.height) +
                             " images, the camera's are " + size_text(camera.width, camera.height));
    r.warp = warp;
    r.identity = warp.identity();
    if (r.identity) return;
    cl::Context& ctx = rt.context();
    if (!map_xy()) {
      // Padded by 8 pairs outside any image (the last work-item of the last row reads them).
      std::vector<float> xy(2 * (map.map_x.size() + 8), -1e6f);
      for (size_t i = 0; i < map.map_x.size(); ++i) {
        xy[2 * i] = map.map_x[i];
        xy[2 * i + 1] = map.map_y[i];
      }
      map_xy = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, xy.size() * sizeof(float), xy.data());
      const PixelRegion reg = camera.region();
      roi = {{static_cast<float>(reg.x), static_cast<float>(reg.y), static_cast<float>(reg.x + reg.width - 1),
              static_cast<float>(reg.y + reg.height - 1)}};
    }
    const size_t field = warp.delta.size() * sizeof(float), bytes = 2 * field;
    if (!r.buffer() || r.buffer.getInfo<CL_MEM_SIZE>() != bytes) r.buffer = cl::Buffer(ctx, CL_MEM_READ_WRITE, bytes);
    // Blocking: the next call may change r.warp before a non-blocking write had read it.
    rt.queue().enqueueWriteBuffer(r.buffer, CL_TRUE, 0, field, r.warp.delta.data());
    rt.queue().enqueueWriteBuffer(r.buffer, CL_TRUE, field, field, r.warp.light.data());
  }

  void undistort() { undistort(frame, row_warp); }
  void undistort(const cl::Buffer& source, const Rows& r) {
    const cl::Buffer& level0 = prefilter ? raw : intensity[0];
    const cl::Buffer& undistorted = photometric ? uncorrected : level0;
    if (r.identity)
      kernels.undistort(source, map_index, map_weights, w(0), h(0), undistorted);
    else
      kernels.undistort_rolling(source, map_xy, r.buffer, r.warp, roi, undistorted);
    undistorted_source = &source;
    undistorted_rolling = !r.identity;
    if (photometric) {
      // The light is fixed to the camera's pixels, which the row warp moves (RowWarp::light); an
      // identity model is the same everywhere.
      const float saturation = static_cast<float>(photometric->options().saturation);
      if (r.identity || photometric->fit().identity)
        kernels.photometric(uncorrected, photometric->model(), saturation, w(0), h(0), level0);
      else
        kernels.photometric_rolling(uncorrected, photometric->model(), r.buffer, r.warp, saturation, level0);
    }
    if (prefilter) kernels.smooth(raw, w(0), h(0), intensity[0]);
  }
  // Undistortion (with the rolling shutter's row warp r and the photometric correction), pyramid
  // and gradients of the frame in `source` into `out`.
  void stages(const cl::Buffer& source, const Rows& r, Pyramid& out) {
    undistort(source, r);
    pyramid();
    gradients(out);
  }
  void pyramid() {
    for (int l = 1; l < levels; ++l)
      kernels.downsample(intensity[static_cast<size_t>(l - 1)], w(l - 1), h(l - 1),
                         intensity[static_cast<size_t>(l)]);
  }
  void gradients(Pyramid& out) {
    const bool lit = decorrelating();
    if (lit && beta_revision != photometric->revision()) make_beta();
    for (int l = 0; l < levels; ++l) {
      const cl::Buffer& dst = out.levels[static_cast<size_t>(l)].data;
      if (lit)
        kernels.gradient_decorrelated(intensity[static_cast<size_t>(l)], w(l), h(l), beta[static_cast<size_t>(l)],
                                      corrected_mean, dst);
      else
        kernels.gradient(intensity[static_cast<size_t>(l)], w(l), h(l), dst);
    }
  }
  void make_beta() {
    const std::vector<cv::Mat> b =
        gradient_noise_beta(corrected_noise_shape(photometric->fit().scale), levels, prefilter);
    beta.resize(b.size());
    for (size_t l = 0; l < b.size(); ++l) {
      const size_t bytes = b[l].total() * b[l].elemSize();
      if (!beta[l]()) beta[l] = cl::Buffer(rt.context(), CL_MEM_READ_ONLY, bytes);
      // Blocking: b is a local.
      rt.queue().enqueueWriteBuffer(beta[l], CL_TRUE, 0, bytes, b[l].ptr<float>());
    }
    beta_revision = photometric->revision();
  }
};

ImagePipeline::ImagePipeline(ocl::Runtime& runtime, const CameraModel& camera, int levels,
                             const ImagePipelineOptions& options) {
  check_levels(levels, "image pipeline");
  UndistortMap map = compute_undistort_map(camera);  // validates the camera
  impl_ = std::make_unique<Impl>(runtime, options);
  Impl& m = *impl_;
  m.camera = camera;
  m.levels = levels;
  m.map = std::move(map);
  m.row_warp.warp = m.kept_row_warp.warp = identity_row_warp(camera.width, camera.height);
  PipelineKernels::DeviceMap dm = PipelineKernels::device_map(m.map);
  // Zeroed, so that the bytes after the frame that the kernel reads (with weight 0) are defined.
  std::vector<uint8_t> zeros(PipelineKernels::frame_buffer_size(camera.width, camera.height), 0);
  try {
    cl::Context& ctx = runtime.context();
    const cl_mem_flags in = CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR;
    m.frame = cl::Buffer(ctx, in, zeros.size(), zeros.data());
    m.map_index = cl::Buffer(ctx, in, dm.index.size() * sizeof(cl_int), dm.index.data());
    m.map_weights = cl::Buffer(ctx, in, dm.weights.size() * sizeof(float), dm.weights.data());
    for (int l = 0; l < levels; ++l)
      m.intensity.emplace_back(ctx, CL_MEM_READ_WRITE,
                               static_cast<size_t>(m.w(l)) * static_cast<size_t>(m.h(l)) * sizeof(float));
    if (m.prefilter)
      m.raw = cl::Buffer(ctx, CL_MEM_READ_WRITE,
                         static_cast<size_t>(m.w(0)) * static_cast<size_t>(m.h(0)) * sizeof(float));
    if (options.photometric.enabled) {
      m.uncorrected = cl::Buffer(ctx, CL_MEM_READ_WRITE,
                                 static_cast<size_t>(m.w(0)) * static_cast<size_t>(m.h(0)) * sizeof(float));
      const cv::Mat valid(camera.height, camera.width, CV_8UC1, m.map.valid.data());
      m.photometric = std::make_unique<PhotometricModel>(runtime, valid, options.photometric);
    }
  } catch (const cl::Error& e) {
    throw_opencl("allocating buffers for " + size_text(camera.width, camera.height), e);
  }
}

ImagePipeline::~ImagePipeline() = default;

int ImagePipeline::width() const { return impl_->camera.width; }
int ImagePipeline::height() const { return impl_->camera.height; }
int ImagePipeline::levels() const { return impl_->levels; }
const CameraModel& ImagePipeline::camera() const { return impl_->camera; }
const UndistortMap& ImagePipeline::map() const { return impl_->map; }

void ImagePipeline::process(const uint8_t* gray, int width, int height, size_t stride, Pyramid& out) {
  Impl& m = *impl_;
  m.check_frame(gray, width, height, stride);
  m.ensure(out);
  try {
    m.upload(gray, stride);
    m.has_frame = true;
    m.note_mean(gray, stride);
    m.stages(m.frame, m.row_warp, out);
  } catch (const cl::Error& e) {
    throw_opencl("processing a frame", e);
  }
}

void ImagePipeline::process(const cv::Mat& gray, Pyramid& out) {
  if (gray.type() != CV_8UC1)
    throw_invalid_argument("image pipeline: the frame must be 8-bit grey (CV_8UC1)");
  process(gray.ptr<uint8_t>(), gray.cols, gray.rows, gray.step[0], out);
}

void ImagePipeline::learn() {
  Impl& m = *impl_;
  if (!m.photometric || !m.photometric->learning() || !m.has_frame) return;
  try {
    // The undistorted frame is still in `uncorrected` (until the next process or reprocess). The
    // model is per pixel of the global shutter's undistortion (a fixed map of the camera's
    // pixels), so a frame undistorted with a row warp is undistorted again without it.
    if (m.undistorted_rolling)
      m.kernels.undistort(*m.undistorted_source, m.map_index, m.map_weights, m.w(0), m.h(0), m.uncorrected);
    m.kernels.photometric_learn(m.uncorrected, m.photometric->statistics(), m.photometric->next_alpha(),
                                m.w(0), m.h(0));
  } catch (const cl::Error& e) {
    throw_opencl("learning the photometric model", e);
  }
}

void ImagePipeline::reprocess(Pyramid& out) {
  Impl& m = *impl_;
  if (!m.has_frame) throw_invalid_argument("image pipeline: reprocess before any frame");
  m.ensure(out);
  try {
    m.stages(m.frame, m.row_warp, out);
  } catch (const cl::Error& e) {
    throw_opencl("reprocessing a frame", e);
  }
}

void ImagePipeline::keep() {
  Impl& m = *impl_;
  if (!m.has_frame) throw_invalid_argument("image pipeline: keep before any frame");
  const size_t bytes = PipelineKernels::frame_buffer_size(m.camera.width, m.camera.height);
  try {
    if (!m.has_kept) m.kept = cl::Buffer(m.rt.context(), CL_MEM_READ_WRITE, bytes);
    m.rt.queue().enqueueCopyBuffer(m.frame, m.kept, 0, 0, bytes);
    m.has_kept = true;
    m.kept_row_warp.warp = m.row_warp.warp;
    m.kept_row_warp.identity = m.row_warp.identity;
    if (!m.row_warp.identity) {
      const size_t rb = 2 * m.row_warp.warp.delta.size() * sizeof(float);
      if (!m.kept_row_warp.buffer() || m.kept_row_warp.buffer.getInfo<CL_MEM_SIZE>() != rb)
        m.kept_row_warp.buffer = cl::Buffer(m.rt.context(), CL_MEM_READ_WRITE, rb);
      m.rt.queue().enqueueCopyBuffer(m.row_warp.buffer, m.kept_row_warp.buffer, 0, 0, rb);
    }
  } catch (const cl::Error& e) {
    throw_opencl("keeping a frame", e);
  }
}

void ImagePipeline::reprocess_kept(Pyramid& out) {
  Impl& m = *impl_;
  if (!m.has_kept) throw_invalid_argument("image pipeline: reprocess_kept before keep");
  m.ensure(out);
  try {
    m.stages(m.kept, m.kept_row_warp, out);
  } catch (const cl::Error& e) {
    throw_opencl("reprocessing the kept frame", e);
  }
}

void ImagePipeline::set_row_warp(const RowWarp& warp) {
  try {
    impl_->set_rows(impl_->row_warp, warp);
  } catch (const cl::Error& e) {
    throw_opencl("setting the row warp", e);
  }
}

void ImagePipeline::set_kept_row_warp(const RowWarp& warp) {
  try {
    impl_->set_rows(impl_->kept_row_warp, warp);
  } catch (const cl::Error& e) {
    throw_opencl("setting the kept frame's row warp", e);
  }
}

PhotometricModel* ImagePipeline::photometric() { return impl_->photometric.get(); }

PipelineTimings ImagePipeline::process_timed(const cv::Mat& gray, Pyramid& out) {
  if (gray.type() != CV_8UC1)
    throw_invalid_argument("image pipeline: the frame must be 8-bit grey (CV_8UC1)");
  Impl& m = *impl_;
  m.check_frame(gray.ptr<uint8_t>(), gray.cols, gray.rows, gray.step[0]);
  m.ensure(out);
  PipelineTimings t;
  try {
    cl::CommandQueue& q = m.rt.queue();
    q.finish();
    auto t0 = std::chrono::steady_clock::now();
    m.upload(gray.ptr<uint8_t>(), gray.step[0]);
    m.has_frame = true;
    m.note_mean(gray.ptr<uint8_t>(), gray.step[0]);
    q.finish();
    t.upload_ms = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    m.undistort();
    q.finish();
    t.undistort_ms = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    m.pyramid();
    q.finish();
    t.pyramid_ms = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    m.gradients(out);
    q.finish();
    t.gradient_ms = ms_since(t0);
  } catch (const cl::Error& e) {
    throw_opencl("processing a frame", e);
  }
  return t;
}

}  // namespace planarvo
