// The mosaic's per-frame warp: parameters, plain C++ reference, OpenCL host side
// (mosaic_warp.h).
#include "mosaic/mosaic_warp.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "core/error.h"
#include "core/tasks.h"

namespace planarvo::mosaic {

WarpSetup make_warp_setup(const CameraModel& camera, const Extrinsics& extrinsics, double max_range, double feather) {
  if (!(extrinsics.z > 0) || !std::isfinite(extrinsics.z))
    throw_invalid_argument("mosaic: the camera height (extrinsics z) must be positive");
  if (!(max_range > 0) || !std::isfinite(max_range)) throw_invalid_argument("mosaic: the range limit must be positive");
  if (!(feather > 0) || !std::isfinite(feather)) throw_invalid_argument("mosaic: the feathering ramp must be positive");
  WarpSetup s;
  s.camera = camera;
  s.extrinsics = extrinsics;
  s.max_range = max_range;
  s.feather = feather;
  // The border of the region of interest, every pixel: its undistorted rays bound the domain.
  double m = 0;
  for_each_border_pixel(camera.region(), 1,
                        [&](double u, double v) { m = std::max(m, camera.unproject({u, v}).squaredNorm()); });
  s.max_radius2 = m;
  return s;
}

namespace {

// The homography (window pixel -> camera-frame ground point, in camera heights) at a robot pose,
// and the camera centre in the trajectory's frame (when camera_centre is not null).
Eigen::Matrix3d window_homography(const WarpSetup& setup, const SE2& pose, const MosaicGrid& grid,
                                  const Window& window, Eigen::Vector3d* camera_centre = nullptr) {
  // Camera in the trajectory's frame: T_wc = T_wv T_vc; a ground point P = (X, Y, 0) is at
  // R_cw (P - C) in the camera, i.e. [c1 c2 -R_cw C] (X, Y, 1) with c_i the columns of R_cw.
  const Eigen::Matrix4d T_wc = pose.matrix3d() * setup.extrinsics.T_vc();
  const Eigen::Matrix3d R_cw = T_wc.topLeftCorner<3, 3>().transpose();
  const Eigen::Vector3d C = T_wc.topRightCorner<3, 1>();
  Eigen::Matrix3d G;
  G.col(0) = R_cw.col(0);
  G.col(1) = R_cw.col(1);
  G.col(2) = -R_cw * C;
  // Window pixel (col, row) -> ground (X, Y, 1): X = ox + (wx + col) r, Y = oy + (h - wy - row) r.
  const double res = grid.resolution;
  Eigen::Matrix3d A;
  A << res, 0, grid.origin.x() + window.x * res,  //
      0, -res, grid.origin.y() + (grid.height - window.y) * res,  //
      0, 0, 1;
  if (camera_centre) *camera_centre = C;
  // Scaled so that the camera-frame coordinates are in units of the camera height: the same
  // homography up to scale, with float-friendly magnitudes.
  return (G * A) / setup.extrinsics.z;
}

void put_homography(const Eigen::Matrix3d& H, int at, WarpParams* p) {
  for (int i = 0; i < 9; ++i) (*p)[static_cast<size_t>(at + i)] = static_cast<float>(H(i / 3, i % 3));
}

}  // namespace

WarpParams warp_params(const WarpSetup& setup, const SE2& pose, const MosaicGrid& grid, const Window& window) {
  Eigen::Vector3d C;
  const Eigen::Matrix3d H = window_homography(setup, pose, grid, window, &C);
  const double res = grid.resolution;
  WarpParams p{};
  put_homography(H, kParamH, &p);
  put_homography(H, kParamHMiddle, &p);
  put_homography(H, kParamHLast, &p);
  const CameraModel& c = setup.camera;
  const double intr[4] = {c.fx, c.fy, c.cx, c.cy};
  const double dist[5] = {c.k1, c.k2, c.p1, c.p2, c.k3};
  for (int i = 0; i < 4; ++i) p[static_cast<size_t>(kParamIntrinsics + i)] = static_cast<float>(intr[i]);
  for (int i = 0; i < 5; ++i) p[static_cast<size_t>(kParamDistortion + i)] = static_cast<float>(dist[i]);
  p[kParamMaxRadius2] = static_cast<float>(setup.max_radius2);
  const PixelRegion r = c.region();
  p[kParamRegion + 0] = static_cast<float>(r.x);
  p[kParamRegion + 1] = static_cast<float>(r.y);
  p[kParamRegion + 2] = static_cast<float>(r.x + r.width - 1);
  p[kParamRegion + 3] = static_cast<float>(r.y + r.height - 1);
  p[kParamInvFeather] = static_cast<float>(1.0 / setup.feather);
  // The foot point: the camera centre projected onto the ground, in window pixels.
  p[kParamFoot + 0] = static_cast<float>((C.x() - grid.origin.x()) / res - window.x);
  p[kParamFoot + 1] = static_cast<float>(grid.height - (C.y() - grid.origin.y()) / res - window.y);
  const double range_px = setup.max_range / res;
  p[kParamRange2] = static_cast<float>(range_px * range_px);
  p[kParamInvRows] = 0.0f;
  return p;
}

WarpParams warp_params(const WarpSetup& setup, const std::array<SE2, 3>& row_poses, const MosaicGrid& grid,
                       const Window& window) {
  WarpParams p = warp_params(setup, row_poses[0], grid, window);
  if (!(setup.camera.rolling_shutter_readout > 0) || setup.camera.height < 2) return p;
  put_homography(window_homography(setup, row_poses[1], grid, window), kParamHMiddle, &p);
  put_homography(window_homography(setup, row_poses[2], grid, window), kParamHLast, &p);
  p[kParamInvRows] = static_cast<float>(1.0 / (setup.camera.height - 1));
  return p;
}

namespace {

// The kernel's projection of window pixel (mx, my) at readout fraction s: false where the ground
// point is behind the camera or outside the distortion model's domain.
bool project_reference(const WarpParams& prm, float mx, float my, float s, float* u, float* v) {
  return pv_mosaic_project(prm.data(), mx, my, s, u, v) != 0;
}

}  // namespace

cv::Mat mosaic_warp_reference(const cv::Mat& frame, const WarpParams& prm, int width, int height) {
  if (frame.type() != CV_8UC1) throw_invalid_argument("mosaic_warp_reference: the frame must be CV_8UC1");
  cv::Mat out(height, width, CV_32FC2);
  const int stride = static_cast<int>(frame.step[0]);
  const uint8_t* data = frame.ptr<uint8_t>();
  const float inv_rows = prm[kParamInvRows];
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) {
      const float mx = static_cast<float>(col) + 0.5f, my = static_cast<float>(row) + 0.5f;
      const float dx = mx - prm[24], dy = my - prm[25];
      float value = 0.0f, weight = 0.0f, u = 0.0f, v = 0.0f;
      bool seen = dx * dx + dy * dy <= prm[26] && project_reference(prm, mx, my, 0.0f, &u, &v);
      // The row that saw the point: s = v(s) / (rows - 1), iterated until it stands still.
      for (int k = 0; seen && inv_rows > 0.0f && k < 100; ++k) {
        const float s = std::clamp(v * inv_rows, 0.0f, 1.0f);
        const float v_before = v;
        seen = project_reference(prm, mx, my, s, &u, &v);
        if (std::abs(v - v_before) < 1e-4f) break;
      }
      if (seen && u >= prm[19] && v >= prm[20] && u < prm[21] && v < prm[22]) {
        const float u0 = std::floor(u), v0 = std::floor(v);
        const float fu = u - u0, fv = v - v0;
        const uint8_t* p = data + static_cast<int>(v0) * stride + static_cast<int>(u0);
        const float a = p[0], b = p[1], c = p[stride], d = p[stride + 1];
        const float top = a + fu * (b - a);
        const float bottom = c + fu * (d - c);
        value = top + fv * (bottom - top);
        const float edge = std::min(std::min(u - prm[19], prm[21] - u), std::min(v - prm[20], prm[22] - v));
        weight = std::min(1.0f, (edge + 0.5f) * prm[23]);
      }
      out.at<cv::Vec2f>(row, col) = cv::Vec2f(value, weight);
    }
  return out;
}

// ---------------------------------------------------------------------------------------------
// OpenCL

std::string MosaicWarp::build_options() { return ""; }

namespace {
// The default, registered before main() so that `planarvo kernels --export` exports it.
const bool kDefaultOptionsRegistered = [] {
  ocl::Runtime::register_build_options("mosaic", MosaicWarp::build_options(), {tasks::kMosaic});
  return true;
}();
}  // namespace

struct MosaicWarp::Impl {
  explicit Impl(ocl::Runtime& r) : runtime(r) {}
  ocl::Runtime& runtime;
  cl::Kernel kernel;
  size_t wg_x = 16, wg_y = 4;
  int frame_width = 0, frame_height = 0;
  cl::Buffer frame, prm, out;
  size_t out_bytes = 0;
};

MosaicWarp::MosaicWarp(ocl::Runtime& runtime, int frame_width, int frame_height)
    : impl_(std::make_unique<Impl>(runtime)) {
  Impl& m = *impl_;
  if (frame_width <= 0 || frame_height <= 0) throw_invalid_argument("MosaicWarp: the frame size must be positive");
  m.frame_width = frame_width;
  m.frame_height = frame_height;
  const std::string opts = build_options();
  ocl::Runtime::register_build_options("mosaic", opts);
  try {
    m.kernel = cl::Kernel(runtime.program("mosaic", opts), "mosaic_warp");
    const auto wg = m.kernel.getWorkGroupInfo<CL_KERNEL_COMPILE_WORK_GROUP_SIZE>(runtime.device());
    m.wg_x = wg[0];
    m.wg_y = wg[1];
    cl::Context& ctx = runtime.context();
    m.frame = cl::Buffer(ctx, CL_MEM_READ_ONLY,
                         static_cast<size_t>(frame_width) * static_cast<size_t>(frame_height));
    m.prm = cl::Buffer(ctx, CL_MEM_READ_ONLY, kParamCount * sizeof(float));
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::OpenCL,
                std::string("mosaic: setting up the warp kernel failed: ") + e.what() + " " + ocl::error_name(e.err()));
  }
}

MosaicWarp::~MosaicWarp() = default;

void MosaicWarp::run(const cv::Mat& frame, const WarpParams& params, int width, int height, cv::Mat* out) {
  Impl& m = *impl_;
  if (frame.type() != CV_8UC1 || frame.cols != m.frame_width || frame.rows != m.frame_height)
    throw_invalid_argument("MosaicWarp::run: the frame must be CV_8UC1 of " + std::to_string(m.frame_width) + "x" +
                           std::to_string(m.frame_height));
  if (width <= 0 || height <= 0) throw_invalid_argument("MosaicWarp::run: empty window");
  out->create(height, width, CV_32FC2);
  const size_t bytes = static_cast<size_t>(width) * static_cast<size_t>(height) * 2 * sizeof(float);
  try {
    cl::CommandQueue& q = m.runtime.queue();
    if (bytes > m.out_bytes) {
      m.out = cl::Buffer(m.runtime.context(), CL_MEM_WRITE_ONLY, bytes);
      m.out_bytes = bytes;
    }
    const cv::Mat packed = frame.isContinuous() ? frame : frame.clone();
    q.enqueueWriteBuffer(m.frame, CL_FALSE, 0, packed.total(), packed.ptr());
    q.enqueueWriteBuffer(m.prm, CL_FALSE, 0, kParamCount * sizeof(float), params.data());
    m.kernel.setArg(0, m.frame);
    m.kernel.setArg(1, static_cast<cl_int>(m.frame_width));
    m.kernel.setArg(2, m.prm);
    m.kernel.setArg(3, static_cast<cl_int>(width));
    m.kernel.setArg(4, static_cast<cl_int>(height));
    m.kernel.setArg(5, m.out);
    const size_t gx = (static_cast<size_t>(width) + m.wg_x - 1) / m.wg_x * m.wg_x;
    const size_t gy = (static_cast<size_t>(height) + m.wg_y - 1) / m.wg_y * m.wg_y;
    q.enqueueNDRangeKernel(m.kernel, cl::NullRange, cl::NDRange(gx, gy), cl::NDRange(m.wg_x, m.wg_y));
    q.enqueueReadBuffer(m.out, CL_TRUE, 0, bytes, out->ptr());
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::OpenCL, std::string("mosaic: the warp kernel failed: ") + e.what() + " " +
                                       ocl::error_name(e.err()));
  }
}

}  // namespace planarvo::mosaic
