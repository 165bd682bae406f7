// kernels/track/motion_search.cl against its plain C++ reference (motion_search_reference, double
// accumulation) on random float4 levels with invalid regions and random homographies, some of
// which send most pixels outside the live level; sizes that are not multiples of the work-group,
// several subsampling steps and work-group sizes, 1 to 300 hypotheses. Each comparison follows
// a run over other homographies, so a row the kernel did not write would hold that run's sums.
// And the search itself: a live level that is the reference moved by a known motion is found
// again (the best peak within a grid step of it).
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "ocl/runtime.h"
#include "track/motion_search.h"
#include "track/warp_model.h"

namespace planarvo::track {
namespace {

std::vector<float> random_level(std::mt19937& rng, int w, int h) {
  std::uniform_real_distribution<float> I(0.0f, 255.0f), u01(0.0f, 1.0f);
  std::vector<float> d(static_cast<size_t>(w) * h * 4);
  for (size_t i = 0; i < d.size(); i += 4) {
    d[i] = I(rng);
    d[i + 3] = u01(rng) < 0.05f ? 0.0f : 1.0f;
  }
  const int x0 = static_cast<int>(u01(rng) * w), y0 = static_cast<int>(u01(rng) * h);
  for (int y = y0; y < std::min(h, y0 + h / 4); ++y)
    for (int x = x0; x < std::min(w, x0 + w / 4); ++x) d[4 * (static_cast<size_t>(y) * w + x) + 3] = 0.0f;
  for (size_t i = 0; i < d.size(); i += 4)
    if (d[i + 3] == 0.0f) d[i] = 0.0f;
  return d;
}

std::vector<Eigen::Matrix3d> random_homographies(std::mt19937& rng, int n, int w, int h) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Matrix3d> out;
  for (int k = 0; k < n; ++k) {
    const double a = 0.2 * u(rng), s = 1.0 + 0.1 * u(rng);
    // Every tenth sends the level mostly outside the live one.
    const double far = k % 10 == 9 ? 0.9 : 0.2;
    Eigen::Matrix3d H;
    H << s * std::cos(a), -s * std::sin(a), far * w * u(rng),  //
        s * std::sin(a), s * std::cos(a), far * h * u(rng),    //
        5e-4 * u(rng), 5e-4 * u(rng), 1.0;
    out.push_back(H);
  }
  return out;
}

cl::Buffer upload(ocl::Runtime& rt, const std::vector<float>& d) {
  cl::Buffer b(rt.context(), CL_MEM_READ_ONLY, d.size() * sizeof(float));
  rt.queue().enqueueWriteBuffer(b, CL_TRUE, 0, d.size() * sizeof(float), d.data());
  return b;
}

TEST(MotionSearchKernel, MatchesReference) {
  ocl::Runtime rt;
  std::mt19937 rng(23);
  struct Case {
    int rw, rh, lw, lh, step, wg, hyps;
  };
  for (const Case& c : {Case{80, 60, 80, 60, 1, 64, 300}, Case{37, 23, 41, 19, 1, 16, 7}, Case{160, 120, 160, 120, 2, 64, 50},
                        Case{53, 71, 50, 70, 3, 128, 1}, Case{9, 9, 9, 9, 1, 8, 20}}) {
    SCOPED_TRACE(std::to_string(c.rw) + "x" + std::to_string(c.rh) + " step " + std::to_string(c.step) + " wg " +
                 std::to_string(c.wg) + " hypotheses " + std::to_string(c.hyps));
    MotionSearch search(rt, c.wg);
    const std::vector<float> ref = random_level(rng, c.rw, c.rh), live = random_level(rng, c.lw, c.lh);
    const cl::Buffer ref_b = upload(rt, ref), live_b = upload(rt, live);
    std::vector<SearchSums> got;
    search.run(ref_b, c.rw, c.rh, live_b, c.lw, c.lh, random_homographies(rng, c.hyps, c.lw, c.lh), c.step, &got);
    const std::vector<Eigen::Matrix3d> H = random_homographies(rng, c.hyps, c.lw, c.lh);
    search.run(ref_b, c.rw, c.rh, live_b, c.lw, c.lh, H, c.step, &got);
    const std::vector<SearchSums> want =
        motion_search_reference({ref.data(), c.rw, c.rh, c.rw}, {live.data(), c.lw, c.lh, c.lw}, H, c.step);
    ASSERT_EQ(got.size(), want.size());
    int with_pixels = 0;
    for (size_t k = 0; k < want.size(); ++k) {
      SCOPED_TRACE("hypothesis " + std::to_string(k));
      const SearchSums& g = got[k];
      const SearchSums& w = want[k];
      // A sample on a pixel boundary may fall either side in float: a pixel or two.
      EXPECT_NEAR(g.n, w.n, 2.0);
      const double tol = 1e-4 * (w.saa + w.sbb) + 2.0 * 255.0 * 255.0;
      EXPECT_NEAR(g.saa, w.saa, tol);
      EXPECT_NEAR(g.sbb, w.sbb, tol);
      EXPECT_NEAR(g.sab, w.sab, tol);
      EXPECT_NEAR(g.sa, w.sa, 1e-4 * std::sqrt(w.n * w.saa) + 2.0 * 255.0);
      EXPECT_NEAR(g.sb, w.sb, 1e-4 * std::sqrt(w.n * w.sbb) + 2.0 * 255.0);
      if (w.n >= 100) {
        ++with_pixels;
        EXPECT_NEAR(g.correlation(), w.correlation(), 0.02);
      }
    }
    if (c.hyps >= 20 && c.rw * c.rh >= 1000) {
      EXPECT_GT(with_pixels, c.hyps / 2);
    }
  }
}

// A smooth random texture level (intensity only; the search reads no gradients).
std::vector<float> smooth_level(std::mt19937& rng, int w, int h) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<float> d(static_cast<size_t>(w) * h * 4, 0.0f);
  std::vector<std::array<double, 4>> waves;
  for (int k = 0; k < 24; ++k) waves.push_back({0.05 + 0.4 * u(rng), 0.05 + 0.4 * u(rng), 6.283 * u(rng), 2.0 * u(rng) - 1.0});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double v = 128.0;
      for (const auto& wv : waves) v += 8.0 * std::sin(wv[0] * x * wv[3] + wv[1] * y + wv[2]);
      d[4 * (static_cast<size_t>(y) * w + x)] = static_cast<float>(v);
      d[4 * (static_cast<size_t>(y) * w + x) + 3] = 1.0f;
    }
  return d;
}

// The live level: the reference seen through a known motion's homography (inverse warp,
// bilinear), plus noise(); pixels whose source falls outside stay invalid.
template <typename Noise>
std::vector<float> render_live(const std::vector<float>& ref, const Eigen::Matrix3d& K, const Extrinsics& e,
                               const SE2& truth, int w, int h, Noise noise) {
  // live(w(p)) = ref(p): live(q) = ref(H^-1 q).
  const Eigen::Matrix3d Hinv = motion_homography(K, e, truth).H.inverse();
  std::vector<float> live(ref.size(), 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3d p = Hinv * Eigen::Vector3d(x, y, 1);
      const double u = p.x() / p.z(), v = p.y() / p.z();
      const int iu = static_cast<int>(std::floor(u)), iv = static_cast<int>(std::floor(v));
      if (iu < 0 || iv < 0 || iu >= w - 1 || iv >= h - 1) continue;
      const double ax = u - iu, ay = v - iv;
      auto at = [&](int xx, int yy) { return ref[4 * (static_cast<size_t>(yy) * w + xx)]; };
      live[4 * (static_cast<size_t>(y) * w + x)] = static_cast<float>(
          (1 - ax) * (1 - ay) * at(iu, iv) + ax * (1 - ay) * at(iu + 1, iv) + (1 - ax) * ay * at(iu, iv + 1) +
          ax * ay * at(iu + 1, iv + 1) + noise());
      live[4 * (static_cast<size_t>(y) * w + x) + 3] = 1.0f;
    }
  return live;
}

// The live level rendered from the reference through a known motion's homography (inverse warp,
// bilinear): the search's best peak lies within one grid step (in the image's shift) of it.
TEST(MotionSearchKernel, FindsAKnownMotion) {
  ocl::Runtime rt;
  std::mt19937 rng(5);
  const int w = 80, h = 60;
  Eigen::Matrix3d K;
  K << 51.2, 0, 39.75, 0, 51.2, 29.75, 0, 0, 1;  // level 3 of a 640x480 camera, f 410
  Extrinsics e;
  e.x = 0.24;
  e.z = 0.18;
  e.pitch = 0.3;
  e.roll = 0.2;
  e.yaw = -0.16;
  // The camera matrix as level 0's, for candidates(): K is level 3's.
  Eigen::Matrix3d K0;
  K0 << 409.6, 0, (K(0, 2) + 0.5) * 8 - 0.5, 0, 409.6, (K(1, 2) + 0.5) * 8 - 0.5, 0, 0, 1;
  const std::vector<float> ref = smooth_level(rng, w, h);
  MotionSearch search(rt);
  MotionSearchOptions o;
  for (const SE2& truth : {SE2(0.02, 0.001, 0.01), SE2(-0.015, 0.006, -0.02), SE2(0.001, -0.012, 0.03)}) {
    SCOPED_TRACE("truth " + std::to_string(truth.x) + " " + std::to_string(truth.y) + " " + std::to_string(truth.theta));
    const std::vector<float> live = render_live(ref, K, e, truth, w, h, [] { return 0.0; });
    Pyramid rp, lp;
    rp.levels.resize(4);
    lp.levels.resize(4);
    rp.levels[3] = {w, h, upload(rt, ref)};
    lp.levels[3] = {w, h, upload(rt, live)};
    const std::vector<SE2> peaks = search.candidates(rp, lp, 3, K0, e, SE2(), o);
    ASSERT_FALSE(peaks.empty());
    // The best peak moves the image's pixels by at most about a grid step from the truth.
    EXPECT_LT(max_pixel_displacement(K, e, peaks[0], truth, w, h), 2.0 * o.grid_px);
  }
}

// A floor that repeats within the search's reach: a pattern with a period of 10 pixels of the
// level, the live level that pattern moved and noisy (as a light or pixel noise leaves a real
// match short of 1). Every period scores alike, so the search returns no peak rather than one
// that may be a neighbouring period (MotionSearchOptions::max_ambiguity); with the test off it
// returns its peaks. The same noise on a random texture leaves its peak distinct.
TEST(MotionSearchKernel, ARepeatingFloorIsAmbiguous) {
  ocl::Runtime rt;
  const int w = 80, h = 60;
  Eigen::Matrix3d K0;
  K0 << 409.6, 0, 319.5, 0, 409.6, 239.5, 0, 0, 1;
  Extrinsics e;  // straight down, 0.18 m
  e.z = 0.18;
  const Eigen::Matrix3d K = level_camera_matrix(K0, 3);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 12.0);
  std::vector<float> periodic(static_cast<size_t>(w) * h * 4, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      periodic[4 * (static_cast<size_t>(y) * w + x)] =
          static_cast<float>(128.0 + 40.0 * std::sin(6.2832 * x / 10.0) + 40.0 * std::sin(6.2832 * y / 10.0));
      periodic[4 * (static_cast<size_t>(y) * w + x) + 3] = 1.0f;
    }
  const std::vector<float> textured = smooth_level(rng, w, h);
  const SE2 truth(0.012, 0.004, 0.0);
  MotionSearch search(rt);
  for (int kind = 0; kind < 2; ++kind) {
    const std::vector<float>& ref = kind == 0 ? periodic : textured;
    SCOPED_TRACE(kind == 0 ? "periodic" : "textured");
    const std::vector<float> live = render_live(ref, K, e, truth, w, h, [&] { return noise(rng); });
    Pyramid rp, lp;
    rp.levels.resize(4);
    lp.levels.resize(4);
    rp.levels[3] = {w, h, upload(rt, ref)};
    lp.levels[3] = {w, h, upload(rt, live)};
    MotionSearchOptions o;
    const std::vector<SE2> peaks = search.candidates(rp, lp, 3, K0, e, SE2(), o);
    if (kind == 0) {
      EXPECT_TRUE(peaks.empty()) << peaks.size() << " peaks";
      o.max_ambiguity = 1.0;
      EXPECT_FALSE(search.candidates(rp, lp, 3, K0, e, SE2(), o).empty());
    } else {
      ASSERT_FALSE(peaks.empty());
      EXPECT_LT(max_pixel_displacement(K, e, peaks[0], truth, w, h), 2.0 * o.grid_px);
    }
  }
}

}  // namespace
}  // namespace planarvo::track
