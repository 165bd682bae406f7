// kernels/track/select_pixels.cl against select_pixels_reference and against the rule itself (each
// block's entry is its level's pixel at the hashed offset, or none where that pixel is invalid or
// outside; the offsets are spread evenly over the block), and the fused pass over subsampled
// pixels (warp_reduce.cl with SELECT) against two references: its own plain C++ reference,
// and the plain pass over a copy of the level in which every pixel that was not selected is made
// invalid (the same pixels, so the same sums).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ocl/runtime.h"
#include "track/pixel_selection.h"
#include "track/warp_reduce.h"

namespace planarvo::track {
namespace {

// Random intensities and gradients (some flat pixels, some invalid ones, an invalid rectangle).
std::vector<float> random_level(std::mt19937& rng, int w, int h) {
  std::uniform_real_distribution<float> I(0.0f, 255.0f), g(-30.0f, 30.0f), u01(0.0f, 1.0f);
  std::vector<float> d(static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
  for (size_t i = 0; i < d.size(); i += 4) {
    d[i] = I(rng);
    const bool flat = u01(rng) < 0.2f;
    d[i + 1] = flat ? 0.1f * g(rng) : g(rng);
    d[i + 2] = flat ? 0.1f * g(rng) : g(rng);
    d[i + 3] = u01(rng) < 0.05f ? 0.0f : 1.0f;
  }
  for (int y = h / 3; y < h / 2; ++y)
    for (int x = w / 4; x < w / 2; ++x) d[4 * (static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)) + 3] = 0.0f;
  for (size_t i = 0; i < d.size(); i += 4)
    if (d[i + 3] == 0.0f) d[i] = d[i + 1] = d[i + 2] = 0.0f;
  return d;
}

cl::Buffer upload(ocl::Runtime& rt, const std::vector<float>& v) {
  return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(float),
                    const_cast<float*>(v.data()));
}

std::vector<float> select_on_device(ocl::Runtime& rt, const std::vector<float>& level, int w, int h, int block,
                                    SelectedPixels* sel) {
  PixelSelector selector(rt);
  PyramidLevel L;
  L.width = w;
  L.height = h;
  L.data = upload(rt, level);
  selector.run(L, 0, block, sel);
  std::vector<float> out(static_cast<size_t>(sel->grid_w) * static_cast<size_t>(sel->grid_h) * 4);
  rt.queue().enqueueReadBuffer(sel->data, CL_TRUE, 0, out.size() * sizeof(float), out.data());
  return out;
}

class SelectPixels : public ::testing::Test {
 protected:
  ocl::Runtime rt_;
};

TEST_F(SelectPixels, TakesOnePixelPerBlockAtAnEvenlySpreadOffset) {
  std::mt19937 rng(11);
  const int sizes[][2] = {{97, 61}, {160, 120}, {5, 3}};
  for (const auto& s : sizes)
    for (int block : {2, 3, 4}) {
      const int w = s[0], h = s[1];
      SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + " block " + std::to_string(block));
      const std::vector<float> level = random_level(rng, w, h);
      SelectedPixels sel;
      const std::vector<float> dev = select_on_device(rt_, level, w, h, block, &sel);
      ASSERT_EQ(sel.grid_w, (w + block - 1) / block);
      ASSERT_EQ(sel.grid_h, (h + block - 1) / block);
      EXPECT_EQ(dev, select_pixels_reference({level.data(), w, h, w}, block));
      // The rule, checked directly on the level: the entry is the pixel at the block's offset.
      std::vector<int> count(static_cast<size_t>(block * block), 0);
      for (int by = 0; by < sel.grid_h; ++by)
        for (int bx = 0; bx < sel.grid_w; ++bx) {
          const float* e = &dev[4 * (static_cast<size_t>(by) * static_cast<size_t>(sel.grid_w) + static_cast<size_t>(bx))];
          const int off = static_cast<int>(select_offset(bx, by, block));
          ASSERT_GE(off, 0);
          ASSERT_LT(off, block * block);
          ++count[static_cast<size_t>(off)];
          const int x = bx * block + off % block, y = by * block + off / block;
          const bool inside = x < w && y < h;
          const float* p = inside ? &level[4 * (static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x))] : nullptr;
          if (!inside || p[3] == 0.0f) {
            EXPECT_EQ(e[3], 0.0f) << "block " << bx << "," << by;
            continue;
          }
          EXPECT_EQ(e[3], static_cast<float>(1 + off % block + 256 * (off / block)));
          EXPECT_EQ(e[0], p[0]);
          EXPECT_EQ(e[1], p[1]);
          EXPECT_EQ(e[2], p[2]);
        }
      // Every offset about equally often (a jittered grid, not a lattice): within 5 standard
      // deviations of a uniform choice where there are enough blocks.
      const double n = static_cast<double>(sel.grid_w) * sel.grid_h, m = n / (block * block);
      if (n >= 1000) {
        for (int c : count) EXPECT_NEAR(c, m, 5.0 * std::sqrt(m)) << "an offset's share";
      }
    }
}

TEST_F(SelectPixels, FusedPassOverSelectedPixelsIsThePassOverThosePixels) {
  std::mt19937 rng(5);
  const int w = 130, h = 77;
  const std::vector<float> ref = random_level(rng, w, h);
  // The live level: the reference's intensities moved by a small warp and some noise, so that
  // residuals are small (inliers) and large (outliers) as in tracking.
  std::vector<float> live = random_level(rng, w + 4, h + 3);
  Eigen::Matrix3d H;
  H << 1.01, -0.02, 1.3, 0.02, 1.01, 0.7, 1e-5, -2e-5, 1.0;
  WarpInputs in;
  in.H = H;
  in.nparam = 3;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 3; ++i)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) in.G[static_cast<size_t>(i)](r, c) = u(rng) * (r == 2 ? 1e-3 : (c == 2 ? 30.0 : 1.0));
  in.gain = 1.05;
  in.bias = -3.0;
  in.huber_k = 60.0;
  for (int block : {2, 3}) {
    SCOPED_TRACE("block " + std::to_string(block));
    SelectedPixels sel;
    const std::vector<float> grid = select_on_device(rt_, ref, w, h, block, &sel);
    // The level with only the selected pixels valid.
    std::vector<float> masked(ref.size(), 0.0f);
    for (int by = 0; by < sel.grid_h; ++by)
      for (int bx = 0; bx < sel.grid_w; ++bx) {
        const float* e = &grid[4 * (static_cast<size_t>(by) * static_cast<size_t>(sel.grid_w) + static_cast<size_t>(bx))];
        if (e[3] == 0.0f) continue;
        const int code = static_cast<int>(e[3]) - 1;  // ox + 256 oy
        const size_t i = 4 * (static_cast<size_t>(by * block + code / 256) * static_cast<size_t>(w) +
                              static_cast<size_t>(bx * block + code % 256));
        std::copy(&ref[i], &ref[i] + 4, &masked[i]);
      }
    for (bool stats : {false, true}) {
      WarpReduceOptions o;
      o.stats = stats;
      o.select_block = block;
      ReduceLayout L;
      L.stats = stats;
      L.hist_bins = stats ? o.hist_bins : 0;
      WarpReduce wr(rt_, 3, o);
      const cl::Buffer blive = upload(rt_, live);
      ReduceSums k;
      wr.run(sel.data, sel.grid_w, sel.grid_h, blive, w + 4, h + 3, in, &k);
      const ReduceSums r = warp_reduce_reference({grid.data(), sel.grid_w, sel.grid_h, sel.grid_w},
                                                  {live.data(), w + 4, h + 3, w + 4}, in, L, o);
      WarpReduceOptions dense;
      dense.stats = stats;
      const ReduceSums m = warp_reduce_reference({masked.data(), w, h, w}, {live.data(), w + 4, h + 3, w + 4}, in, L, dense);
      ASSERT_GT(r.valid, 100.0);
      EXPECT_EQ(r.ref, m.ref);
      EXPECT_EQ(r.valid, m.valid);
      EXPECT_EQ(r.inlier, m.inlier);
      EXPECT_NEAR(r.cost, m.cost, 1e-12 * m.cost);
      EXPECT_LT((r.JtWJ - m.JtWJ).norm(), 1e-12 * m.JtWJ.norm());
      EXPECT_LT((r.JtWr - m.JtWr).norm(), 1e-12 * m.JtWr.norm());
      // Kernel against its reference: float accumulation, a pixel may flip at a cell border.
      EXPECT_EQ(k.ref, r.ref);
      EXPECT_NEAR(k.valid, r.valid, 1.0);
      EXPECT_NEAR(k.cost, r.cost, 2e-5 * r.cost);
      for (int i = 0; i < L.nj(); ++i) {
        for (int j = i; j < L.nj(); ++j)
          EXPECT_NEAR(k.JtWJ(i, j), r.JtWJ(i, j), 1e-4 * std::sqrt(r.JtWJ(i, i) * r.JtWJ(j, j))) << i << "," << j;
        EXPECT_NEAR(k.JtWr(i), r.JtWr(i), 1e-4 * std::sqrt(r.JtWJ(i, i) * r.wrr)) << i;
      }
      EXPECT_EQ(k.clusters, r.clusters);
      if (stats) {
        EXPECT_NEAR(k.glive, r.glive, 2e-5 * r.glive);
        EXPECT_NEAR(k.gref, r.gref, 2e-5 * r.gref);
        EXPECT_NEAR(k.hist_valid, r.hist_valid, 1.0);
        EXPECT_NEAR(r.gref, m.gref, 1e-12 * m.gref);
      }
    }
  }
}

}  // namespace
}  // namespace planarvo::track
