// kernels/track/warp_reduce.cl against its plain C++ reference (warp_reduce_reference, double
// accumulation) on random float4 levels with invalid regions, random homographies and
// derivative matrices, random brightness and Huber thresholds; sizes that are not multiples of
// the work-group's span; several work-group shapes, pixels per work-item, parameter counts and
// histogram sizes. The partials are poisoned first: every row must be written, nothing after.
// Also the host's per-cluster score outer products (ReduceSums::score_outer) against the
// reference's, and the inlier J^T J of the STATS variant.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "ocl/runtime.h"
#include "track/warp_reduce.h"

namespace planarvo::track {
namespace {

// A random level: smooth-ish random intensities (0..255) and unrelated random gradients, with
// invalid rectangles and scattered invalid pixels (all four channels zero there).
std::vector<float> random_level(std::mt19937& rng, int w, int h) {
  std::uniform_real_distribution<float> I(0.0f, 255.0f), g(-40.0f, 40.0f), u01(0.0f, 1.0f);
  std::vector<float> d(static_cast<size_t>(w) * h * 4);
  for (size_t i = 0; i < d.size(); i += 4) {
    d[i] = I(rng);
    d[i + 1] = g(rng);
    d[i + 2] = g(rng);
    d[i + 3] = u01(rng) < 0.03f ? 0.0f : 1.0f;
  }
  for (int k = 0; k < 3; ++k) {
    const int x0 = static_cast<int>(u01(rng) * w), y0 = static_cast<int>(u01(rng) * h);
    const int x1 = std::min(w, x0 + 1 + static_cast<int>(u01(rng) * w / 4));
    const int y1 = std::min(h, y0 + 1 + static_cast<int>(u01(rng) * h / 4));
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) d[4 * (static_cast<size_t>(y) * w + x) + 3] = 0.0f;
  }
  for (size_t i = 0; i < d.size(); i += 4)
    if (d[i + 3] == 0.0f) d[i] = d[i + 1] = d[i + 2] = 0.0f;
  return d;
}

// A homography close to a similarity that keeps most pixels inside the live level, with some
// perspective; derivative matrices random of the size real generators have.
WarpInputs random_inputs(std::mt19937& rng, int nparam, int w, int h) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  WarpInputs in;
  in.nparam = nparam;
  const double a = 0.1 * u(rng), s = 1.0 + 0.05 * u(rng);
  Eigen::Matrix3d H;
  H << s * std::cos(a), -s * std::sin(a), 0.1 * w * u(rng),  //
      s * std::sin(a), s * std::cos(a), 0.1 * h * u(rng),    //
      2e-4 * u(rng), 2e-4 * u(rng), 1.0;
  in.H = H;
  for (int i = 0; i < nparam; ++i) {
    Eigen::Matrix3d G;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) G(r, c) = u(rng) * (r == 2 ? 1e-3 : (c == 2 ? 50.0 : 1.0));
    in.G[static_cast<size_t>(i)] = G;
  }
  in.gain = std::exp(0.1 * u(rng));
  in.bias = 10.0 * u(rng);
  in.huber_k = 20.0 + 30.0 * (u(rng) + 1.0);
  return in;
}

float poison() {
  const uint32_t b = 0x7fc0dead;
  float v;
  std::memcpy(&v, &b, sizeof v);
  return v;
}

struct Variant {
  int nparam;
  WarpReduceOptions options;
};

// Runs the kernel directly on poisoned partials with a guard region; returns the summed row
// and counts the rows not written and guard values touched.
std::vector<double> run_direct(ocl::Runtime& rt, const Variant& v, const std::vector<float>& ref,
                               int rw, int rh, const std::vector<float>& live, int lw, int lh,
                               const WarpInputs& in, int* unwritten, int* guard_touched) {
  ReduceLayout L;
  L.nparam = v.nparam;
  L.stats = v.options.stats;
  L.hist_bins = v.options.stats ? v.options.hist_bins : 0;
  cl::Kernel k(rt.program("warp_reduce", WarpReduce::build_options(v.nparam, v.options)),
               "warp_reduce");
  const size_t wx = static_cast<size_t>(v.options.wg_x), wy = static_cast<size_t>(v.options.wg_y);
  const size_t span = wx * static_cast<size_t>(v.options.pixels_per_item);
  const size_t gx = (static_cast<size_t>(rw) + span - 1) / span, gy = (static_cast<size_t>(rh) + wy - 1) / wy;
  const size_t rows = gx * gy, count = static_cast<size_t>(L.count()), guard = 29;
  std::vector<float> partials(rows * count + guard, poison());
  std::vector<float> params(static_cast<size_t>(9 * (v.nparam + 1)));
  for (int i = 0; i < 9; ++i) params[static_cast<size_t>(i)] = static_cast<float>(in.H(i / 3, i % 3));
  for (int p = 0; p < v.nparam; ++p)
    for (int i = 0; i < 9; ++i)
      params[static_cast<size_t>(9 + 9 * p + i)] = static_cast<float>(in.G[static_cast<size_t>(p)](i / 3, i % 3));
  cl::Context& ctx = rt.context();
  auto buf = [&](const std::vector<float>& x, cl_mem_flags f) {
    return cl::Buffer(ctx, f | CL_MEM_COPY_HOST_PTR, x.size() * sizeof(float), const_cast<float*>(x.data()));
  };
  cl::Buffer bref = buf(ref, CL_MEM_READ_ONLY), blive = buf(live, CL_MEM_READ_ONLY);
  cl::Buffer bpar = buf(params, CL_MEM_READ_ONLY), bout = buf(partials, CL_MEM_READ_WRITE);
  int a = 0;
  k.setArg(a++, bref);
  k.setArg(a++, rw);
  k.setArg(a++, rw);
  k.setArg(a++, rh);
  k.setArg(a++, blive);
  k.setArg(a++, lw);
  k.setArg(a++, lw);
  k.setArg(a++, lh);
  k.setArg(a++, bpar);
  k.setArg(a++, static_cast<float>(in.gain));
  k.setArg(a++, static_cast<float>(in.bias));
  k.setArg(a++, static_cast<float>(in.huber_k));
  k.setArg(a++, bout);
  rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(gx * wx, gy * wy), cl::NDRange(wx, wy));
  rt.queue().enqueueReadBuffer(bout, CL_TRUE, 0, partials.size() * sizeof(float), partials.data());
  *unwritten = 0;
  *guard_touched = 0;
  std::vector<double> sum(count, 0.0);
  for (size_t r = 0; r < rows; ++r) {
    bool ok = true;
    for (size_t o = 0; o < count; ++o) {
      const float x = partials[r * count + o];
      if (std::isnan(x)) ok = false;
      sum[o] += x;
    }
    *unwritten += ok ? 0 : 1;
  }
  for (size_t i = rows * count; i < partials.size(); ++i) {
    uint32_t b, p;
    std::memcpy(&b, &partials[i], 4);
    const float pv = poison();
    std::memcpy(&p, &pv, 4);
    *guard_touched += b != p;
  }
  return sum;
}

// Compares kernel sums with the reference. Tolerances: each J^T W J entry within 2e-5 of
// sqrt(JtWJ_ii JtWJ_jj) (its Cauchy-Schwarz bound), each J^T W r entry within 2e-5 of
// sqrt(JtWJ_ii wrr), the cost and squared sums within 2e-5 relative; pixel counts within
// `flips` (a pixel whose warped position lies within float rounding of a cell boundary may be
// decided differently), histogram bins likewise.
void expect_sums_match(const ReduceSums& k, const ReduceSums& r, int nj, double flips) {
  const double rel = 2e-5;
  // One flipped pixel moves a sum by at most its largest term; allow that on top.
  const double per_pixel = flips > 0 ? flips / std::max(1.0, r.valid) : 0.0;
  for (int i = 0; i < nj; ++i) {
    for (int j = i; j < nj; ++j) {
      const double scale = std::sqrt(r.JtWJ(i, i) * r.JtWJ(j, j));
      EXPECT_NEAR(k.JtWJ(i, j), r.JtWJ(i, j), (rel + 5 * per_pixel) * scale + 1e-6)
          << "JtWJ(" << i << "," << j << ")";
    }
    EXPECT_NEAR(k.JtWr(i), r.JtWr(i), (rel + 5 * per_pixel) * std::sqrt(r.JtWJ(i, i) * r.wrr) + 1e-6)
        << "JtWr(" << i << ")";
  }
  EXPECT_NEAR(k.cost, r.cost, (rel + 5 * per_pixel) * r.cost + 1e-6);
  EXPECT_NEAR(k.wrr, r.wrr, (rel + 5 * per_pixel) * r.wrr + 1e-6);
  EXPECT_NEAR(k.valid, r.valid, flips);
  EXPECT_NEAR(k.inlier, r.inlier, flips + 1);
  EXPECT_EQ(k.ref, r.ref);
  ASSERT_EQ(k.has_stats, r.has_stats);
  if (!r.has_stats) return;
  EXPECT_NEAR(k.rr, r.rr, (rel + 5 * per_pixel) * r.rr + 1e-6);
  EXPECT_NEAR(k.iref, r.iref, 1e-5 * std::sqrt(r.iref2 * r.valid) + 128 * flips + 1e-3);
  EXPECT_NEAR(k.iref2, r.iref2, 1e-5 * r.iref2 + 16384 * flips + 1e-3);
  EXPECT_NEAR(k.glive, r.glive, (rel + 5 * per_pixel) * r.glive + 1e-3);
  EXPECT_NEAR(k.gref, r.gref, (rel + 5 * per_pixel) * r.gref + 1e-3);
  ASSERT_EQ(k.hist_bins, r.hist_bins);
  EXPECT_NEAR(k.hist_valid, r.hist_valid, flips);
  for (int j = 0; j < r.hist_bins; ++j)
    EXPECT_NEAR(k.hist[static_cast<size_t>(j)], r.hist[static_cast<size_t>(j)], flips + 1) << "bin " << j;
  // J^T J over the inliers: like J^T W J, and a pixel may flip between inlier and outlier.
  ASSERT_EQ(k.JtJ_inlier.rows(), nj);
  for (int i = 0; i < nj; ++i)
    for (int j = i; j < nj; ++j) {
      const double scale = std::sqrt(r.JtJ_inlier(i, i) * r.JtJ_inlier(j, j));
      EXPECT_NEAR(k.JtJ_inlier(i, j), r.JtJ_inlier(i, j), (rel + 5 * (per_pixel + 1.0 / std::max(1.0, r.inlier))) * scale + 1e-6)
          << "JtJ_inlier(" << i << "," << j << ")";
    }
}

// The cluster-robust score outer products of the host class (from the kernel's rows) and of the
// reference (per pixel): the same clusters, the same extrapolation. Each entry within 1e-3 of
// sqrt(M_ii M_jj) (observed 7e-7..1e-4 with 2-16 clusters). With one cluster the
// extrapolated score is zero up to rounding (it is the whole pass's, which the extrapolation
// cancels): only finite there.
void expect_score_outer_match(const ReduceSums& k, const ReduceSums& r, int nj) {
  ASSERT_EQ(k.clusters, r.clusters);
  ASSERT_GT(r.clusters, 0.0);
  ASSERT_EQ(k.score_outer.rows(), nj);
  EXPECT_TRUE(k.score_outer.allFinite());
  if (r.clusters < 2) return;
  double worst = 0.0;
  for (int i = 0; i < nj; ++i)
    for (int j = i; j < nj; ++j) {
      const double scale = std::sqrt(r.score_outer(i, i) * r.score_outer(j, j));
      EXPECT_NEAR(k.score_outer(i, j), r.score_outer(i, j), 1e-3 * scale) << "score_outer(" << i << "," << j << ")";
      worst = std::max(worst, std::abs(k.score_outer(i, j) - r.score_outer(i, j)) / scale);
    }
  std::printf("score_outer: %.0f clusters, largest difference %.2g of sqrt(M_ii M_jj)\n", r.clusters, worst);
}

class WarpReduceKernel : public ::testing::Test {
 protected:
  ocl::Runtime rt_;
};

TEST_F(WarpReduceKernel, MatchesReferenceOnRandomLevels) {
  std::mt19937 rng(4242);
  std::vector<Variant> variants;
  WarpReduceOptions o;
  variants.push_back({3, o});  // the defaults
  o.stats = true;
  variants.push_back({3, o});  // the defaults with statistics
  o.wg_x = 16; o.wg_y = 4; o.pixels_per_item = 1; o.lanes = 1; o.hist_bins = 0; o.fast_math = false;
  variants.push_back({3, o});
  o.wg_x = 32; o.wg_y = 2; o.pixels_per_item = 3; o.hist_bins = 12; o.fast_math = true;
  variants.push_back({5, o});
  o.wg_x = 8; o.wg_y = 1; o.pixels_per_item = 8; o.lanes = 8; o.hist_bins = 16; o.stats = false;
  variants.push_back({1, o});
  o.stats = true; o.cluster_width = 200; o.cluster_bands = 3;  // 3 work-groups x a third of the rows
  variants.push_back({3, o});
  o.wg_x = 16; o.wg_y = 2; o.pixels_per_item = 16;  // two runs of 8 per work-item
  o.cluster_width = 128; o.cluster_bands = 8;
  variants.push_back({3, o});
  const int sizes[][4] = {{97, 61, 101, 67}, {160, 120, 160, 120}, {33, 7, 40, 9}};
  for (const Variant& v : variants) {
    for (const auto& s : sizes) {
      const int rw = s[0], rh = s[1], lw = s[2], lh = s[3];
      SCOPED_TRACE(WarpReduce::build_options(v.nparam, v.options) + ", reference " +
                   std::to_string(rw) + "x" + std::to_string(rh));
      const std::vector<float> ref = random_level(rng, rw, rh), live = random_level(rng, lw, lh);
      const WarpInputs in = random_inputs(rng, v.nparam, lw, lh);
      ReduceLayout L;
      L.nparam = v.nparam;
      L.stats = v.options.stats;
      L.hist_bins = v.options.stats ? v.options.hist_bins : 0;
      const ReduceSums r = warp_reduce_reference({ref.data(), rw, rh, rw}, {live.data(), lw, lh, lw}, in, L,
                                                  v.options);
      ASSERT_GT(r.valid, 0.3 * rw * rh) << "the random warp should keep most pixels inside";

      int unwritten = 0, touched = 0;
      const std::vector<double> row = run_direct(rt_, v, ref, rw, rh, live, lw, lh, in, &unwritten, &touched);
      EXPECT_EQ(unwritten, 0) << "rows of partials not written";
      EXPECT_EQ(touched, 0) << "values after the last row written";
      ReduceSums k;
      k.assign(L, row.data());
      expect_sums_match(k, r, L.nj(), 2.0);

      // The host class gives the same sums (same kernel, same order: bit-identical rows).
      WarpReduce wr(rt_, v.nparam, v.options);
      cl::Buffer bref(rt_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, ref.size() * 4, const_cast<float*>(ref.data()));
      cl::Buffer blive(rt_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, live.size() * 4, const_cast<float*>(live.data()));
      ReduceSums c;
      wr.run(bref, rw, rh, blive, lw, lh, in, &c);
      EXPECT_EQ(c.cost, k.cost);
      EXPECT_EQ(c.JtWJ, k.JtWJ);
      EXPECT_EQ(c.JtWr, k.JtWr);
      expect_score_outer_match(c, r, L.nj());
      // Deterministic: a second run is bit-identical.
      ReduceSums c2;
      wr.run(bref, rw, rh, blive, lw, lh, in, &c2);
      EXPECT_EQ(c2.JtWJ, c.JtWJ);
      EXPECT_EQ(c2.JtWr, c.JtWr);
      EXPECT_EQ(c2.cost, c.cost);
      EXPECT_EQ(c2.score_outer, c.score_outer);
    }
  }
}

TEST_F(WarpReduceKernel, IdentityWarpOfALevelOnItselfHasZeroResidual) {
  // H = I, gain 1, bias 0: every valid pixel has r = 0, the ESM gradient is the level's own.
  std::mt19937 rng(7);
  const int w = 70, h = 45;
  const std::vector<float> lvl = random_level(rng, w, h);
  WarpInputs in = random_inputs(rng, 3, w, h);
  in.H.setIdentity();
  in.gain = 1.0;
  in.bias = 0.0;
  // Without -cl-fast-relaxed-math: with it, 1 / q.z may be an approximate reciprocal, which
  // puts an integer position a rounding error below the integer, in the cell to its left.
  WarpReduceOptions o;
  o.fast_math = false;
  o.stats = true;
  WarpReduce wr(rt_, 3, o);
  cl::Buffer b(rt_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, lvl.size() * 4, const_cast<float*>(lvl.data()));
  ReduceSums s;
  wr.run(b, w, h, b, w, h, in, &s);
  EXPECT_EQ(s.rr, 0.0);
  EXPECT_EQ(s.inlier, s.valid);
  EXPECT_EQ(s.glive, s.gref);
  // Every pixel an inlier of weight 1: the inlier J^T J is J^T W J; no residual, no score.
  EXPECT_EQ(s.JtJ_inlier, s.JtWJ);
  EXPECT_EQ(s.score_outer.norm(), 0.0);
  EXPECT_GT(s.clusters, 0.0);
  // A pixel is valid when it and its right, lower and lower-right neighbours are valid and
  // inside: count that directly.
  int expected = 0, refs = 0;
  auto valid = [&](int x, int y) { return lvl[4 * (static_cast<size_t>(y) * w + x) + 3] != 0.0f; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      refs += valid(x, y);
      expected += x + 1 < w && y + 1 < h && valid(x, y) && valid(x + 1, y) && valid(x, y + 1) && valid(x + 1, y + 1);
    }
  EXPECT_EQ(s.valid, expected);
  EXPECT_EQ(s.ref, refs);
  ASSERT_EQ(s.hist_bins, 16);
  EXPECT_GT(s.hist_valid, 0.0);
  EXPECT_LT(s.hist_valid, s.valid);  // a subsample
  for (int j = 0; j < s.hist_bins; ++j) EXPECT_EQ(s.hist[static_cast<size_t>(j)], s.hist_valid);
}

TEST_F(WarpReduceKernel, DebugVariantWritesEveryPixelConsistentWithTheSums) {
  // The debug variant's per-pixel (r, weight, valid, rho), poisoned first: every reference
  // pixel written, and their sums equal to the reduced sums.
  std::mt19937 rng(99);
  const int w = 75, h = 31;
  const std::vector<float> ref = random_level(rng, w, h), live = random_level(rng, w + 3, h + 2);
  const WarpInputs in = random_inputs(rng, 3, w + 3, h + 2);
  WarpReduceOptions o;
  o.debug_output = true;
  WarpReduce wr(rt_, 3, o);
  cl::Buffer bref(rt_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, ref.size() * 4, const_cast<float*>(ref.data()));
  cl::Buffer blive(rt_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, live.size() * 4, const_cast<float*>(live.data()));
  std::vector<float> dbg(static_cast<size_t>(w) * h * 4 + 16, poison());
  cl::Buffer bdbg(rt_.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, dbg.size() * 4, dbg.data());
  ReduceSums s;
  wr.run(bref, w, h, blive, w + 3, h + 2, in, &s, &bdbg);
  rt_.queue().enqueueReadBuffer(bdbg, CL_TRUE, 0, dbg.size() * 4, dbg.data());
  double sum_r2 = 0, sum_wr2 = 0, sum_valid = 0, sum_rho = 0;
  int unwritten = 0;
  for (int i = 0; i < w * h; ++i) {
    const float* d = &dbg[4 * static_cast<size_t>(i)];
    if (std::isnan(d[0]) || std::isnan(d[1]) || std::isnan(d[2]) || std::isnan(d[3])) ++unwritten;
    sum_r2 += static_cast<double>(d[0]) * d[0];
    sum_wr2 += static_cast<double>(d[1]) * d[0] * d[0];
    sum_valid += d[2];
    sum_rho += d[3];
  }
  EXPECT_EQ(unwritten, 0);
  for (size_t i = static_cast<size_t>(w) * h * 4; i < dbg.size(); ++i) EXPECT_TRUE(std::isnan(dbg[i]));
  EXPECT_EQ(sum_valid, s.valid);
  EXPECT_NEAR(sum_rho, s.cost, 1e-5 * s.cost);
  EXPECT_NEAR(sum_wr2, s.wrr, 1e-5 * s.wrr);
  EXPECT_GT(sum_r2, sum_wr2);  // the random levels have outliers
}

TEST_F(WarpReduceKernel, MedianFromHistogram) {
  ReduceSums s;
  s.hist_bins = 16;
  s.hist_valid = 1000;
  // Residuals uniform in log between thresholds: cumulative counts rise linearly per bin.
  for (int j = 0; j < 16; ++j) s.hist[static_cast<size_t>(j)] = 100.0 * j;
  // Half (500) is reached exactly at bin 5.
  EXPECT_NEAR(s.median_abs_residual(), ReduceLayout::hist_threshold(5), 1e-12);
  s.hist.fill(0.0);
  EXPECT_DOUBLE_EQ(s.median_abs_residual(), ReduceLayout::hist_threshold(15));
  s.hist.fill(1000.0);
  EXPECT_DOUBLE_EQ(s.median_abs_residual(), 0.5 * ReduceLayout::hist_threshold(0));
}

}  // namespace
}  // namespace planarvo::track
