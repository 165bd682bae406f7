// The simulator's renderer: mip pyramid, ray tables, per-frame homography, the OpenCL kernel
// (kernels/sim/render.cl) and its plain C++ reference.
#include <algorithm>
#include <cmath>
#include <string>
#include <thread>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/tasks.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"

namespace planarvo::sim {

namespace {

int next_power_of_two(int n) {
  int p = 1;
  while (p < n) p *= 2;
  return p;
}

// The nearest power of two to n (in ratio), at least 1.
int nearest_power_of_two(int n) {
  const int up = next_power_of_two(n);
  const int down = std::max(1, up / 2);
  return static_cast<double>(up) / n < static_cast<double>(n) / down ? up : down;
}

// Runs body(row_begin, row_end) over rows on two threads (the table builds are one-offs).
template <class F>
void parallel_rows(int rows, F body) {
  const int half = rows / 2;
  std::thread worker([&] { body(half, rows); });
  body(0, half);
  worker.join();
}

// Bilinear lookup in one level of the mirror-tiled pyramid: the transliteration of
// rnd_fold/rnd_bilinear in kernels/sim/render.cl, in the same operations.
inline int fold(int i, int w) {
  const int m = i & (2 * w - 1);
  return m < w ? m : 2 * w - 1 - m;
}

inline float bilinear(const float* tex, int offset, int w, int h, float u, float v) {
  const float x0 = std::floor(u), y0 = std::floor(v);
  const float fx = u - x0, fy = v - y0;
  const int xi = static_cast<int>(x0), yi = static_cast<int>(y0);
  const int xa = fold(xi, w), xb = fold(xi + 1, w);
  const int ya = fold(yi, h), yb = fold(yi + 1, h);
  const float* ra = tex + offset + ya * w;
  const float* rb = tex + offset + yb * w;
  const float top = ra[xa] + fx * (ra[xb] - ra[xa]);
  const float bottom = rb[xa] + fx * (rb[xb] - rb[xa]);
  return top + fy * (bottom - top);
}

}  // namespace

cv::Mat prepare_texture(const cv::Mat& texture, Eigen::Vector2d* texel_scale) {
  if (texture.empty() || texture.channels() != 1 ||
      (texture.depth() != CV_8U && texture.depth() != CV_32F))
    throw_invalid_argument("simulator: the texture must be a non-empty CV_8UC1 or CV_32FC1 image");
  cv::Mat f;
  texture.convertTo(f, CV_32F);
  const int w = nearest_power_of_two(f.cols), h = nearest_power_of_two(f.rows);
  if (w != f.cols || h != f.rows) {
    cv::Mat r;
    cv::resize(f, r, cv::Size(w, h), 0, 0, (w < f.cols || h < f.rows) ? cv::INTER_AREA : cv::INTER_CUBIC);
    f = r;
  }
  if (texel_scale)
    *texel_scale = Eigen::Vector2d(static_cast<double>(texture.cols) / w,
                                   static_cast<double>(texture.rows) / h);
  return f;
}

MipPyramid build_mip_pyramid(const cv::Mat& texture) {
  if (texture.empty() || texture.type() != CV_32FC1 || next_power_of_two(texture.cols) != texture.cols ||
      next_power_of_two(texture.rows) != texture.rows)
    throw_invalid_argument("build_mip_pyramid: needs a CV_32FC1 texture with power-of-two sides");
  MipPyramid m;
  m.width = texture.cols;
  m.height = texture.rows;
  size_t total = 0;
  for (int w = m.width, h = m.height;; w /= 2, h /= 2) {
    m.levels.insert(m.levels.end(), {static_cast<int>(total), w, h});
    total += static_cast<size_t>(w) * static_cast<size_t>(h);
    if (w == 1 || h == 1) break;
  }
  m.data.resize(total);
  for (int r = 0; r < m.height; ++r) {
    const float* src = texture.ptr<float>(r);
    std::copy(src, src + m.width, m.data.begin() + static_cast<std::ptrdiff_t>(r) * m.width);
  }
  for (int l = 1; l < m.num_levels(); ++l) {
    const int po = m.levels[3 * (l - 1)], pw = m.levels[3 * (l - 1) + 1];
    const int o = m.levels[3 * l], w = m.levels[3 * l + 1], h = m.levels[3 * l + 2];
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const float* a = &m.data[static_cast<size_t>(po + 2 * r * pw + 2 * c)];
        const float* b = a + pw;
        m.data[static_cast<size_t>(o + r * w + c)] = 0.25f * ((a[0] + a[1]) + (b[0] + b[1]));
      }
  }
  double sum = 0.0;
  for (int i = 0; i < m.width * m.height; ++i) sum += m.data[static_cast<size_t>(i)];
  m.mean = static_cast<float>(sum / (static_cast<double>(m.width) * m.height));
  return m;
}

RayTable build_ray_table(const CameraModel& camera, int supersampling) {
  camera.validate("simulator camera");
  if (supersampling < 1 || supersampling > 16)
    throw_invalid_argument("build_ray_table: supersampling must be 1 to 16");
  // 2 S^2 + 6 floats per pixel; OpenCL devices need not allocate more than a quarter of their
  // memory in one buffer, and the tables are rebuilt per camera, so keep them moderate.
  const double bytes = 4.0 * (2.0 * supersampling * supersampling + 6.0) * camera.width * camera.height;
  if (bytes > 1024.0 * 1024.0 * 1024.0)
    throw_invalid_argument("simulator: the ray tables for " + std::to_string(camera.width) + "x" +
                           std::to_string(camera.height) + " pixels with supersampling " +
                           std::to_string(supersampling) + " would take " +
                           std::to_string(static_cast<long long>(bytes / (1024 * 1024))) +
                           " MiB (at most 1024): lower the supersampling");
  RayTable t;
  t.width = camera.width;
  t.height = camera.height;
  t.supersampling = supersampling;
  const size_t n = static_cast<size_t>(t.width) * static_cast<size_t>(t.height);
  const int ns = supersampling * supersampling;
  t.pixel.resize(6 * n);
  t.sub.resize(2 * static_cast<size_t>(ns) * n);
  const double inv_s = 1.0 / supersampling;
  parallel_rows(t.height, [&](int r0, int r1) {
    for (int r = r0; r < r1; ++r)
      for (int c = 0; c < t.width; ++c) {
        const size_t p = static_cast<size_t>(r) * static_cast<size_t>(t.width) + static_cast<size_t>(c);
        const Eigen::Vector2d ray = camera.unproject(Eigen::Vector2d(c, r));
        // d(ray)/d(pixel) is the inverse of d(pixel)/d(ray), whose forward model needs no
        // iteration: central differences of distort() at the ray.
        const double h = 1e-6;
        Eigen::Matrix2d D;
        D.col(0) = (camera.distort(ray + Eigen::Vector2d(h, 0)) - camera.distort(ray - Eigen::Vector2d(h, 0))) / (2 * h);
        D.col(1) = (camera.distort(ray + Eigen::Vector2d(0, h)) - camera.distort(ray - Eigen::Vector2d(0, h))) / (2 * h);
        D.row(0) *= camera.fx;
        D.row(1) *= camera.fy;
        const Eigen::Matrix2d J = D.inverse();
        const double vals[6] = {ray.x(), ray.y(), J(0, 0), J(0, 1), J(1, 0), J(1, 1)};
        for (size_t k = 0; k < 6; ++k) t.pixel[k * n + p] = static_cast<float>(vals[k]);
        for (int j = 0; j < supersampling; ++j)
          for (int i = 0; i < supersampling; ++i) {
            const size_t s = static_cast<size_t>(j * supersampling + i);
            Eigen::Vector2d ray_s = ray;
            if (supersampling > 1)
              ray_s = camera.unproject(Eigen::Vector2d(c + (i + 0.5) * inv_s - 0.5, r + (j + 0.5) * inv_s - 0.5));
            t.sub[(2 * s) * n + p] = static_cast<float>(ray_s.x());
            t.sub[(2 * s + 1) * n + p] = static_cast<float>(ray_s.y());
          }
      }
  });
  return t;
}

Eigen::Matrix3d ray_to_texture(const SE2& robot_pose, const Extrinsics& extrinsics,
                               const Eigen::Vector2d& texel, const Eigen::Vector2d& origin) {
  // Camera in the world: T_wc = T_wv T_vc. A ray d (camera coordinates) meets z = 0 at
  // C + s R d with s = -C_z / (r3 . d), r_i the rows of R; so X = C_x - C_z (r1 . d) / (r3 . d).
  const Eigen::Matrix4d T_wc = robot_pose.matrix3d() * extrinsics.T_vc();
  const Eigen::Matrix3d R = T_wc.topLeftCorner<3, 3>();
  const Eigen::Vector3d C = T_wc.topRightCorner<3, 1>();
  Eigen::Matrix3d H;
  H.row(0) = (C.x() / texel.x() - origin.x()) * R.row(2) - (C.z() / texel.x()) * R.row(0);
  H.row(1) = (C.y() / texel.y() - origin.y()) * R.row(2) - (C.z() / texel.y()) * R.row(1);
  H.row(2) = R.row(2);
  return H;
}

FrameParams frame_params(const SE2& robot_pose, const Extrinsics& extrinsics,
                         const Eigen::Vector2d& texel, const MipPyramid& pyramid,
                         int supersampling, bool mipmap) {
  // Whole mirror periods nearest to the camera centre.
  const Eigen::Vector2d centre =
      robot_pose * Eigen::Vector2d(extrinsics.x, extrinsics.y);
  const double px = 2.0 * pyramid.width, py = 2.0 * pyramid.height;
  const Eigen::Vector2d origin(px * std::round(centre.x() / texel.x() / px),
                               py * std::round(centre.y() / texel.y() / py));
  const Eigen::Matrix3d H = ray_to_texture(robot_pose, extrinsics, texel, origin);
  FrameParams p{};
  for (int i = 0; i < 9; ++i) p[static_cast<size_t>(kParamH + i)] = static_cast<float>(H(i / 3, i % 3));
  p[kParamInvS] = 1.0f / static_cast<float>(supersampling);
  p[kParamLodMax] = mipmap ? static_cast<float>(pyramid.num_levels() - 1) : 0.0f;
  p[kParamFar] = pyramid.mean;
  p[kParamInvCount] = 1.0f / static_cast<float>(supersampling * supersampling);
  return p;
}

std::vector<float> row_homographies(const FrameParams& p, int height) {
  std::vector<float> rows(9 * static_cast<size_t>(std::max(height, 0)));
  for (size_t i = 0; i < rows.size(); ++i) rows[i] = p[static_cast<size_t>(kParamH) + i % 9];
  return rows;
}

std::vector<float> row_homographies(const std::vector<FrameParams>& params) {
  std::vector<float> rows(9 * params.size());
  for (size_t y = 0; y < params.size(); ++y)
    for (size_t i = 0; i < 9; ++i) rows[9 * y + i] = params[y][static_cast<size_t>(kParamH) + i];
  return rows;
}

cv::Mat render_reference(const MipPyramid& pyramid, const RayTable& rays, const FrameParams& prm) {
  return render_reference(pyramid, rays, prm, row_homographies(prm, rays.height));
}

cv::Mat render_reference(const MipPyramid& pyramid, const RayTable& rays, const FrameParams& prm,
                         const std::vector<float>& hrows) {
  const int width = rays.width, height = rays.height;
  if (hrows.size() != 9 * static_cast<size_t>(height))
    throw_invalid_argument("render_reference: needs 9 homography entries per image row");
  const int ns = rays.supersampling * rays.supersampling;
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  cv::Mat out(height, width, CV_32FC1);
  const float inv_s = prm[kParamInvS], lod_max = prm[kParamLodMax];
  const float far_value = prm[kParamFar], inv_count = prm[kParamInvCount];
  const float* tex = pyramid.data.data();
  const int* levels = pyramid.levels.data();
  const float* pix = rays.pixel.data();
  const float* sub = rays.sub.data();
  for (int y = 0; y < height; ++y) {
    const float* hy = hrows.data() + 9 * static_cast<size_t>(y);
    const float H0 = hy[0], H1 = hy[1], H2 = hy[2];
    const float H3 = hy[3], H4 = hy[4], H5 = hy[5];
    const float H6 = hy[6], H7 = hy[7], H8 = hy[8];
    for (int x = 0; x < width; ++x) {
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
      const float cx = pix[p], cy = pix[n + p];
      const float j00 = pix[2 * n + p], j01 = pix[3 * n + p];
      const float j10 = pix[4 * n + p], j11 = pix[5 * n + p];
      float lod = lod_max;
      {
        const float g0 = H0 * cx + H1 * cy + H2;
        const float g1 = H3 * cx + H4 * cy + H5;
        const float g2 = H6 * cx + H7 * cy + H8;
        const float iw = 1.0f / g2;
        const float u = g0 * iw, v = g1 * iw;
        const float a00 = (H0 - u * H6) * iw, a01 = (H1 - u * H7) * iw;
        const float a10 = (H3 - v * H6) * iw, a11 = (H4 - v * H7) * iw;
        const float b00 = (a00 * j00 + a01 * j10) * inv_s, b01 = (a00 * j01 + a01 * j11) * inv_s;
        const float b10 = (a10 * j00 + a11 * j10) * inv_s, b11 = (a10 * j01 + a11 * j11) * inv_s;
        const float len2 = std::max(b00 * b00 + b10 * b10, b01 * b01 + b11 * b11);
        if (g2 < 0.0f && len2 < 1e30f)
          lod = len2 <= 1.0f ? 0.0f : std::min(std::max(0.5f * std::log2(std::max(len2, 1e-30f)), 0.0f), lod_max);
      }
      const int l0 = static_cast<int>(lod);
      const int l1 = std::min(l0 + 1, static_cast<int>(lod_max));
      const float f = lod - static_cast<float>(l0);
      const float s0 = 1.0f / static_cast<float>(1 << l0), s1 = 1.0f / static_cast<float>(1 << l1);
      const int o0 = levels[3 * l0], w0 = levels[3 * l0 + 1], h0 = levels[3 * l0 + 2];
      const int o1 = levels[3 * l1], w1 = levels[3 * l1 + 1], h1 = levels[3 * l1 + 2];
      float acc = 0.0f;
      for (int s = 0; s < ns; ++s) {
        const float rx = sub[static_cast<size_t>(2 * s) * n + p];
        const float ry = sub[static_cast<size_t>(2 * s + 1) * n + p];
        const float g0 = H0 * rx + H1 * ry + H2;
        const float g1 = H3 * rx + H4 * ry + H5;
        const float g2 = H6 * rx + H7 * ry + H8;
        const float iw = 1.0f / g2;
        const float u = g0 * iw, v = g1 * iw;
        if (!(g2 < 0.0f && std::abs(u) < 1e7f && std::abs(v) < 1e7f)) {
          acc += far_value;
          continue;
        }
        const float t0 = bilinear(tex, o0, w0, h0, (u + 0.5f) * s0 - 0.5f, (v + 0.5f) * s0 - 0.5f);
        if (f > 0.0f) {
          const float t1 = bilinear(tex, o1, w1, h1, (u + 0.5f) * s1 - 0.5f, (v + 0.5f) * s1 - 0.5f);
          acc += t0 + f * (t1 - t0);
        } else {
          acc += t0;
        }
      }
      out.at<float>(y, x) = acc * inv_count;
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------

struct Renderer::Impl {
  ocl::Runtime& rt;
  Options options;
  Eigen::Vector2d texel;
  MipPyramid pyramid;
  RayTable rays;
  cl::Kernel kernel;
  size_t wg_x = 1, wg_y = 1;  // the kernel's reqd_work_group_size
  cl::Buffer tex, levels, pix, sub, prm, out, hrows;
  explicit Impl(ocl::Runtime& r) : rt(r) {}

  // One launch: the parameter block p (its homography unused) and height x 9 row homographies.
  cv::Mat launch(const FrameParams& p, const std::vector<float>& rows);
};

// The kernel's defaults (RENDER_WG_X x RENDER_WG_Y = 16 x 4; PoCL measured within 10 % of each
// other for 16x4, 32x2, 64x1 and 128x1, and 2-D tiles suit GPUs' caches). The launch reads the
// work-group size back from the compiled kernel, so other -D values need no host change.
std::string Renderer::build_options() { return ""; }

namespace {
// The default, registered before main() so that `planarvo kernels --export` exports it for
// simulation without a renderer having been made (FPGA flows cannot compile at run time).
const bool kDefaultOptionsRegistered = [] {
  ocl::Runtime::register_build_options("render", Renderer::build_options(), {tasks::kSimulate});
  return true;
}();
}  // namespace

Renderer::Renderer(ocl::Runtime& runtime, const cv::Mat& texture, const Options& options)
    : impl_(std::make_unique<Impl>(runtime)) {
  Impl& m = *impl_;
  m.options = options;
  if (!(options.texel_size > 0) || !std::isfinite(options.texel_size))
    throw_invalid_argument("simulator: texel_size must be positive");
  if (!(options.extrinsics.z > 0)) throw_invalid_argument("simulator: extrinsics.z must be positive");
  Eigen::Vector2d scale;
  const cv::Mat prepared = prepare_texture(texture, &scale);
  m.texel = options.texel_size * scale;
  m.pyramid = build_mip_pyramid(prepared);
  m.rays = build_ray_table(options.camera, options.supersampling);

  const std::string opts = build_options();
  ocl::Runtime::register_build_options("render", opts);
  try {
    m.kernel = cl::Kernel(runtime.program("render", opts), "render_ground");
    const auto wg = m.kernel.getWorkGroupInfo<CL_KERNEL_COMPILE_WORK_GROUP_SIZE>(runtime.device());
    m.wg_x = wg[0];
    m.wg_y = wg[1];
    cl::Context& ctx = runtime.context();
    auto upload = [&](const void* data, size_t bytes) {
      return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<void*>(data));
    };
    m.tex = upload(m.pyramid.data.data(), m.pyramid.data.size() * sizeof(float));
    m.levels = upload(m.pyramid.levels.data(), m.pyramid.levels.size() * sizeof(int));
    m.pix = upload(m.rays.pixel.data(), m.rays.pixel.size() * sizeof(float));
    m.sub = upload(m.rays.sub.data(), m.rays.sub.size() * sizeof(float));
    m.prm = cl::Buffer(ctx, CL_MEM_READ_ONLY, kParamCount * sizeof(float));
    m.out = cl::Buffer(ctx, CL_MEM_WRITE_ONLY,
                       static_cast<size_t>(m.rays.width) * static_cast<size_t>(m.rays.height) * sizeof(float));
    m.kernel.setArg(0, m.tex);
    m.kernel.setArg(1, m.levels);
    m.kernel.setArg(2, m.pix);
    m.kernel.setArg(3, m.sub);
    m.kernel.setArg(4, static_cast<cl_int>(options.supersampling * options.supersampling));
    m.kernel.setArg(5, m.prm);
    m.kernel.setArg(6, static_cast<cl_int>(m.rays.width));
    m.kernel.setArg(7, static_cast<cl_int>(m.rays.height));
    m.kernel.setArg(8, m.out);
    m.kernel.setArg(9, static_cast<cl_int>(m.rays.width));
    m.hrows = cl::Buffer(ctx, CL_MEM_READ_ONLY, 9 * static_cast<size_t>(m.rays.height) * sizeof(float));
    m.kernel.setArg(10, m.hrows);
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::OpenCL, std::string("simulator: setting up the render kernel failed: ") +
                                       e.what() + " " + ocl::error_name(e.err()));
  }
}

Renderer::~Renderer() = default;

const MipPyramid& Renderer::pyramid() const { return impl_->pyramid; }
const RayTable& Renderer::rays() const { return impl_->rays; }
Eigen::Vector2d Renderer::texel() const { return impl_->texel; }

FrameParams Renderer::params(const SE2& robot_pose) const {
  return params(robot_pose, impl_->options.extrinsics);
}

FrameParams Renderer::params(const SE2& robot_pose, const Extrinsics& extrinsics) const {
  return frame_params(robot_pose, extrinsics, impl_->texel, impl_->pyramid, impl_->options.supersampling,
                      impl_->options.mipmap);
}

cv::Mat Renderer::render_float(const SE2& robot_pose) {
  return render_float(robot_pose, impl_->options.extrinsics);
}

cv::Mat Renderer::render_float(const SE2& robot_pose, const Extrinsics& extrinsics) {
  const FrameParams p = params(robot_pose, extrinsics);
  return impl_->launch(p, row_homographies(p, impl_->rays.height));
}

cv::Mat Renderer::render_float_rows(const std::vector<SE2>& row_poses) {
  return render_float_rows(row_poses, std::vector<Extrinsics>(row_poses.size(), impl_->options.extrinsics));
}

cv::Mat Renderer::render_float_rows(const std::vector<SE2>& row_poses,
                                    const std::vector<Extrinsics>& row_extrinsics) {
  Impl& m = *impl_;
  if (row_poses.size() != static_cast<size_t>(m.rays.height) || row_extrinsics.size() != row_poses.size())
    throw_invalid_argument("Renderer::render_float_rows: needs one pose and one extrinsics per image row (" +
                           std::to_string(m.rays.height) + "), got " + std::to_string(row_poses.size()) +
                           " and " + std::to_string(row_extrinsics.size()));
  std::vector<FrameParams> rows;
  rows.reserve(row_poses.size());
  for (size_t y = 0; y < row_poses.size(); ++y) rows.push_back(params(row_poses[y], row_extrinsics[y]));
  return m.launch(rows.front(), row_homographies(rows));
}

cv::Mat Renderer::Impl::launch(const FrameParams& p, const std::vector<float>& rows) {
  Impl& m = *this;
  cv::Mat image(m.rays.height, m.rays.width, CV_32FC1);
  try {
    cl::CommandQueue& q = m.rt.queue();
    q.enqueueWriteBuffer(m.prm, CL_TRUE, 0, sizeof(float) * p.size(), p.data());
    q.enqueueWriteBuffer(m.hrows, CL_TRUE, 0, sizeof(float) * rows.size(), rows.data());
    const size_t gx = (static_cast<size_t>(m.rays.width) + m.wg_x - 1) / m.wg_x * m.wg_x;
    const size_t gy = (static_cast<size_t>(m.rays.height) + m.wg_y - 1) / m.wg_y * m.wg_y;
    q.enqueueNDRangeKernel(m.kernel, cl::NullRange, cl::NDRange(gx, gy), cl::NDRange(m.wg_x, m.wg_y));
    q.enqueueReadBuffer(m.out, CL_TRUE, 0, image.total() * sizeof(float), image.ptr<float>());
  } catch (const cl::Error& e) {
    throw Error(ErrorCode::OpenCL, std::string("simulator: rendering failed: ") + e.what() + " " +
                                       ocl::error_name(e.err()));
  }
  return image;
}

cv::Mat Renderer::render(const SE2& robot_pose) {
  cv::Mat f = render_float(robot_pose), out;
  f.convertTo(out, CV_8U);  // rounds to nearest and saturates
  return out;
}

}  // namespace planarvo::sim
