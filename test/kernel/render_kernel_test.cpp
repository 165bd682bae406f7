// kernels/sim/render.cl against its plain C++ reference (render_reference), on random textures,
// cameras, extrinsics and poses, with a poisoned, padded output buffer.
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/random_scene.h"
#include "core/error.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"

namespace planarvo::sim {
namespace {

constexpr float kPoison = -12345.0f;

// Both compute the same float operations; they differ by the compiler's freedom (fused
// multiply-adds, the last bit of log2 and of the reciprocal), so texture coordinates agree to
// a few float roundings of their magnitude. On a noise texture whose neighbouring texels
// differ by up to 255 grey levels, a pixel may then differ by up to
//   kTolerance + 255 * kUlps * 2^-24 * (|u| + |v|),
// (u, v) the pixel centre's texture coordinates (level 0 texels, after the origin shift).
constexpr double kTolerance = 0.01;
constexpr double kUlps = 8.0;

cv::Mat noise_texture(int w, int h, uint64_t seed) {
  Random r(seed);
  cv::Mat t(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) t.at<float>(y, x) = static_cast<float>(255.0 * r.uniform());
  return t;
}

using test::random_camera;
using test::random_extrinsics;

struct KernelRun {
  cv::Mat image;  // width x height
  bool padding_untouched = true;
};

// Runs render_ground directly on its own buffers: output rows padded to a larger stride,
// everything poisoned first.
// The work-group shape is a build option; no options give the kernel's defaults, 16 x 4.
struct WorkGroup {
  size_t x, y;
  bool defaults;
  std::string options() const {
    return defaults ? std::string()
                    : "-D RENDER_WG_X=" + std::to_string(x) + " -D RENDER_WG_Y=" + std::to_string(y);
  }
};

// rows: the per-row homographies (row_homographies); empty: prm's for every row.
KernelRun run_kernel(ocl::Runtime& rt, const MipPyramid& pyr, const RayTable& rays,
                     const FrameParams& prm, const WorkGroup& wg, std::vector<float> rows = {},
                     cl::Program* program = nullptr) {
  if (rows.empty()) rows = row_homographies(prm, rays.height);
  const int w = rays.width, h = rays.height, stride = w + 7;
  cl::Context& ctx = rt.context();
  auto upload = [&](const auto& v) {
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(v[0]),
                      const_cast<void*>(static_cast<const void*>(v.data())));
  };
  cl::Buffer tex = upload(pyr.data), levels = upload(pyr.levels), pix = upload(rays.pixel),
             sub = upload(rays.sub), params = upload(prm), hrows = upload(rows);
  std::vector<float> host(static_cast<size_t>(stride) * static_cast<size_t>(h), kPoison);
  cl::Buffer out(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, host.size() * sizeof(float), host.data());
  cl::Kernel k(program ? *program : rt.program("render", wg.options()), "render_ground");
  const auto compiled = k.getWorkGroupInfo<CL_KERNEL_COMPILE_WORK_GROUP_SIZE>(rt.device());
  EXPECT_EQ(compiled[0], wg.x);
  EXPECT_EQ(compiled[1], wg.y);
  const int ns = rays.supersampling * rays.supersampling;
  k.setArg(0, tex);
  k.setArg(1, levels);
  k.setArg(2, pix);
  k.setArg(3, sub);
  k.setArg(4, ns);
  k.setArg(5, params);
  k.setArg(6, w);
  k.setArg(7, h);
  k.setArg(8, out);
  k.setArg(9, stride);
  if (!program) k.setArg(10, hrows);
  const size_t wx = wg.x, wy = wg.y;
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange,
                                  cl::NDRange((w + wx - 1) / wx * wx, (h + wy - 1) / wy * wy),
                                  cl::NDRange(wx, wy));
  rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, host.size() * sizeof(float), host.data());
  KernelRun r;
  r.image = cv::Mat(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < stride; ++x) {
      const float v = host[static_cast<size_t>(y * stride + x)];
      if (x < w)
        r.image.at<float>(y, x) = v;
      else if (v != kPoison)
        r.padding_untouched = false;
    }
  return r;
}

// rows: the per-row homographies the kernel used; empty: prm's for every row.
void expect_match(const KernelRun& run, const cv::Mat& ref, const RayTable& rays,
                  const FrameParams& prm, const std::string& what, const std::vector<float>& rows = {}) {
  int unwritten = 0, off = 0;
  double worst = 0.0;
  const size_t n = static_cast<size_t>(rays.width) * static_cast<size_t>(rays.height);
  for (int y = 0; y < ref.rows; ++y)
    for (int x = 0; x < ref.cols; ++x) {
      const float k = run.image.at<float>(y, x), r = ref.at<float>(y, x);
      if (k == kPoison) ++unwritten;
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(rays.width) + static_cast<size_t>(x);
      const double rx = rays.pixel[p], ry = rays.pixel[n + p];
      const float* H = rows.empty() ? prm.data() : rows.data() + 9 * static_cast<size_t>(y);
      const double g2 = H[6] * rx + H[7] * ry + H[8];
      const double u = (H[0] * rx + H[1] * ry + H[2]) / g2;
      const double v = (H[3] * rx + H[4] * ry + H[5]) / g2;
      const double scale = g2 < 0 ? std::min(std::abs(u) + std::abs(v), 2e7) : 0.0;
      const double d = std::abs(static_cast<double>(k) - r);
      if (!(d <= kTolerance + 255.0 * kUlps * 0x1.0p-24 * scale)) ++off;
      worst = std::max(worst, d);
    }
  EXPECT_EQ(unwritten, 0) << what;
  EXPECT_EQ(off, 0) << what << ": worst difference " << worst;
  EXPECT_TRUE(run.padding_untouched) << what;
}

TEST(RenderKernel, MatchesReferenceOnRandomScenes) {
  ocl::Runtime rt;
  Random r(2024);
  // Sizes that are not multiples of the work-group, non-square power-of-two textures.
  const int sizes[][2] = {{97, 61}, {160, 120}, {203, 150}};
  const int tex_sizes[][2] = {{256, 256}, {512, 128}, {64, 256}};
  int case_no = 0;
  for (int ss : {1, 2, 3})
    for (int i = 0; i < 3; ++i, ++case_no) {
      const CameraModel cam = random_camera(r, sizes[i][0], sizes[i][1]);
      const Extrinsics e = random_extrinsics(r, 35.0);
      const MipPyramid pyr = build_mip_pyramid(noise_texture(tex_sizes[i][0], tex_sizes[i][1], 7 + case_no));
      const RayTable rays = build_ray_table(cam, ss);
      const Eigen::Vector2d texel(r.uniform(0.0002, 0.002), r.uniform(0.0002, 0.002));
      const SE2 pose(r.uniform(-500, 500), r.uniform(-500, 500), r.uniform(-M_PI, M_PI));
      for (bool mip : {true, false}) {
        const FrameParams prm = frame_params(pose, e, texel, pyr, ss, mip);
        const WorkGroup wg = case_no % 2 ? WorkGroup{16, 4, true} : WorkGroup{32, 1, false};
        expect_match(run_kernel(rt, pyr, rays, prm, wg), render_reference(pyr, rays, prm), rays, prm,
                     "case " + std::to_string(case_no) + (mip ? " mip" : " no mip"));
      }
    }
}

// A camera tilted far enough to see the horizon: rays that miss the ground take the far value.
TEST(RenderKernel, MatchesReferenceAcrossTheHorizon) {
  ocl::Runtime rt;
  CameraModel cam = default_camera(128, 96, 90.0);
  Extrinsics e;
  e.z = 0.3;
  e.pitch = 70.0 * M_PI / 180;
  const MipPyramid pyr = build_mip_pyramid(noise_texture(128, 128, 3));
  const RayTable rays = build_ray_table(cam, 2);
  const FrameParams prm = frame_params(SE2(0.2, 0.1, 0.3), e, Eigen::Vector2d(0.001, 0.001), pyr, 2, true);
  const cv::Mat ref = render_reference(pyr, rays, prm);
  // Part of the image is sky (exactly the far value), part is ground.
  int sky = 0;
  for (int y = 0; y < ref.rows; ++y)
    for (int x = 0; x < ref.cols; ++x) sky += ref.at<float>(y, x) == prm[kParamFar];
  EXPECT_GT(sky, ref.rows * ref.cols / 10);
  EXPECT_LT(sky, ref.rows * ref.cols * 9 / 10);
  expect_match(run_kernel(rt, pyr, rays, prm, {8, 8, false}), ref, rays, prm, "horizon");
}

// The Renderer class runs the same kernel with the same tables.
TEST(RenderKernel, RendererMatchesReference) {
  ocl::Runtime rt;
  Options o;
  o.camera = default_camera(150, 100);
  o.supersampling = 2;
  const cv::Mat texture = noise_texture(256, 256, 5);
  Renderer renderer(rt, texture, o);
  const SE2 pose(3.0, -7.0, 1.0);
  KernelRun run;
  run.image = renderer.render_float(pose);
  const cv::Mat& k = run.image;
  ASSERT_EQ(k.type(), CV_32FC1);
  ASSERT_EQ(k.size(), cv::Size(150, 100));
  expect_match(run, render_reference(renderer.pyramid(), renderer.rays(), renderer.params(pose)),
               renderer.rays(), renderer.params(pose), "renderer");
  const cv::Mat k8 = renderer.render(pose);
  ASSERT_EQ(k8.type(), CV_8UC1);
  for (int y = 0; y < k8.rows; ++y)
    for (int x = 0; x < k8.cols; ++x)
      ASSERT_NEAR(k8.at<uint8_t>(y, x), k.at<float>(y, x), 0.5 + 1e-4);
}

// Row poses of a fast rolling shutter: the robot moves 5 cm and turns 0.3 rad while the rows
// are read, so neighbouring rows' homographies differ.
std::vector<FrameParams> rolling_rows(const SE2& pose, const Extrinsics& e, const Eigen::Vector2d& texel,
                                      const MipPyramid& pyr, int height, int ss, bool mip) {
  std::vector<FrameParams> rows;
  for (int y = 0; y < height; ++y) {
    const double f = static_cast<double>(y) / (height - 1);
    rows.push_back(frame_params(pose * SE2::exp(Eigen::Vector3d(0.05 * f, 0.0, 0.3 * f)), e, texel, pyr, ss, mip));
  }
  return rows;
}

// One homography per output row (a rolling shutter): the kernel against the reference with the
// same rows, on random scenes.
TEST(RenderKernel, PerRowHomographiesMatchReference) {
  ocl::Runtime rt;
  Random r(77);
  const int sizes[][2] = {{97, 61}, {160, 120}};
  for (int i = 0; i < 2; ++i)
    for (int ss : {1, 3}) {
      const CameraModel cam = random_camera(r, sizes[i][0], sizes[i][1]);
      const Extrinsics e = random_extrinsics(r, 35.0);
      const MipPyramid pyr = build_mip_pyramid(noise_texture(256, 128, 11 + i));
      const RayTable rays = build_ray_table(cam, ss);
      const Eigen::Vector2d texel(r.uniform(0.0002, 0.002), r.uniform(0.0002, 0.002));
      const SE2 pose(r.uniform(-500, 500), r.uniform(-500, 500), r.uniform(-M_PI, M_PI));
      const std::vector<FrameParams> per_row = rolling_rows(pose, e, texel, pyr, cam.height, ss, true);
      const std::vector<float> rows = row_homographies(per_row);
      ASSERT_EQ(rows.size(), 9u * static_cast<size_t>(cam.height));
      // The rows do differ (else this would test nothing beyond the global shutter).
      ASSERT_NE(std::memcmp(rows.data(), rows.data() + 9 * (cam.height - 1), 9 * sizeof(float)), 0);
      const std::string what = "size " + std::to_string(i) + " ss " + std::to_string(ss);
      expect_match(run_kernel(rt, pyr, rays, per_row[0], {16, 4, true}, rows),
                   render_reference(pyr, rays, per_row[0], rows), rays, per_row[0], what, rows);
    }
}

// The global shutter (every row the same homography) gives, bit for bit, what the kernel gave
// before it took per-row homographies: that kernel is this one with H read from the parameter
// block (rebuilt here from the current source by undoing that change).
TEST(RenderKernel, GlobalShutterBitIdenticalToSingleHomographyKernel) {
  ocl::Runtime rt;
  std::string source = ocl::program_source("render");
  auto undo = [&](const std::string& now, const std::string& before) {
    const size_t at = source.find(now);
    ASSERT_NE(at, std::string::npos) << "kernels/sim/render.cl changed: update this test's reconstruction (" << now << ")";
    source.replace(at, now.size(), before);
  };
  undo("const int out_stride,\n                   __global const float* hrows) {", "const int out_stride) {");
  undo("__global const float* hy = hrows + 9 * y;\n", "__constant float* hy = prm;\n");
  cl::Program legacy(rt.context(), source);
  legacy.build(std::vector<cl::Device>{rt.device()}, rt.effective_build_options("").c_str());

  Random r(5);
  const CameraModel cam = random_camera(r, 123, 77);
  const Extrinsics e = random_extrinsics(r, 35.0);
  const MipPyramid pyr = build_mip_pyramid(noise_texture(256, 256, 3));
  const Eigen::Vector2d texel(0.0007, 0.0009);
  for (int ss : {1, 3})
    for (bool mip : {true, false}) {
      const RayTable rays = build_ray_table(cam, ss);
      const FrameParams prm = frame_params(SE2(-41.0, 17.0, 2.0), e, texel, pyr, ss, mip);
      const KernelRun now = run_kernel(rt, pyr, rays, prm, {16, 4, true});
      const KernelRun before = run_kernel(rt, pyr, rays, prm, {16, 4, true}, {}, &legacy);
      ASSERT_EQ(now.image.size(), before.image.size());
      EXPECT_EQ(std::memcmp(now.image.data, before.image.data, now.image.total() * sizeof(float)), 0)
          << "ss " << ss << (mip ? " mip" : " no mip");
      // And the reference gives the same whether it is handed the rows or the block.
      const cv::Mat a = render_reference(pyr, rays, prm);
      const cv::Mat b = render_reference(pyr, rays, prm, row_homographies(prm, rays.height));
      EXPECT_EQ(std::memcmp(a.data, b.data, a.total() * sizeof(float)), 0);
    }
}

// Renderer::render_float_rows: row y is row y of a global-shutter render at row y's pose, bit
// for bit (the same kernel, the same homography for that row), and matches the reference.
TEST(RenderKernel, RendererRowsMatchGlobalRendersRowByRow) {
  ocl::Runtime rt;
  Options o;
  o.camera = default_camera(120, 90);
  o.supersampling = 2;
  Renderer renderer(rt, noise_texture(256, 256, 9), o);
  std::vector<SE2> poses;
  for (int y = 0; y < o.camera.height; ++y)
    poses.push_back(SE2(2.0, 1.0, 0.5) * SE2::exp(Eigen::Vector3d(0.004 * y, 0.0, 0.01 * y)));
  const cv::Mat rows = renderer.render_float_rows(poses);
  ASSERT_EQ(rows.type(), CV_32FC1);
  ASSERT_EQ(rows.size(), cv::Size(120, 90));
  for (int y : {0, 1, 44, 89}) {
    const cv::Mat global = renderer.render_float(poses[static_cast<size_t>(y)]);
    EXPECT_EQ(std::memcmp(rows.ptr<float>(y), global.ptr<float>(y), sizeof(float) * 120), 0) << "row " << y;
  }
  std::vector<FrameParams> per_row;
  for (const SE2& p : poses) per_row.push_back(renderer.params(p));
  const std::vector<float> h = row_homographies(per_row);
  KernelRun run;
  run.image = rows;
  expect_match(run, render_reference(renderer.pyramid(), renderer.rays(), per_row[0], h), renderer.rays(),
               per_row[0], "renderer rows", h);
  EXPECT_THROW(renderer.render_float_rows(std::vector<SE2>(3)), Error);
}

}  // namespace
}  // namespace planarvo::sim
