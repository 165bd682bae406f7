// The tracker's fused warp-residual-Jacobian-reduction pass (kernels/track/warp_reduce.cl): the
// layout of its per-work-group partial sums, its plain C++ reference, and the host side that
// runs it and sums the partials in double. What one pass computes is documented at the top of
// the kernel; the residual is r = gain * I_l(w(p)) + bias - I_r(p) with gain = e^a.
#pragma once
#include <array>
#include <string>
#include <vector>

#include <CL/opencl.hpp>
#include <Eigen/Core>

#include "kernels/track/warp_reduce_layout.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::track {

// The most parameters of the homography a pass can take (NPARAM), and of histogram bins.
inline constexpr int kMaxParams = 8;
inline constexpr int kMaxJacobian = kMaxParams + 2;  // plus brightness (a, b)
inline constexpr int kMaxHistBins = 24;

// Where each sum sits in a row of partials: kernels/track/warp_reduce_layout.h, the layout the
// kernel writes by. The statistics from rr() on exist only in the STATS variant.
struct ReduceLayout {
  int nparam = 3;
  bool stats = false;
  int hist_bins = 16;  // with stats only

  int nj() const { return nparam + 2; }
  int nh() const { return PV_REDUCE_NH(nj()); }
  // Upper triangle of J^T W J, row by row; i <= j.
  int jtj(int i, int j) const { return PV_REDUCE_JTJ + PV_REDUCE_JTJ_AT(nj(), i, j); }
  int jtr(int i) const { return PV_REDUCE_JTR(nj()) + i; }
  int cost() const { return PV_REDUCE_COST(nj()); }
  int wrr() const { return PV_REDUCE_WRR(nj()); }
  int valid() const { return PV_REDUCE_VALID(nj()); }
  int inlier() const { return PV_REDUCE_INLIER(nj()); }
  int ref() const { return PV_REDUCE_REF(nj()); }
  int rr() const { return PV_REDUCE_RR(nj()); }
  int iref() const { return PV_REDUCE_IREF(nj()); }
  int iref2() const { return PV_REDUCE_IREF2(nj()); }
  int glive() const { return PV_REDUCE_GLIVE(nj()); }
  int gref() const { return PV_REDUCE_GREF(nj()); }
  int hvalid() const { return PV_REDUCE_HVALID(nj()); }  // valid pixels in the histogram's subsample
  int hist(int j) const { return PV_REDUCE_HIST(nj()) + j; }
  // Upper triangle of J^T J over the inliers (|r| <= k, unweighted), row by row; i <= j.
  int jtj_inlier(int i, int j) const { return PV_REDUCE_JTJ_IN(nj(), hist_bins) + PV_REDUCE_JTJ_AT(nj(), i, j); }
  int count() const { return stats ? PV_REDUCE_STATS_COUNT(nj(), hist_bins) : PV_REDUCE_PLAIN_COUNT(nj()); }
  // Histogram bin j counts |r| < hist_threshold(j) = 0.25 * 2^(j / 2) grey levels.
  static double hist_threshold(int j);
};

using MatrixJ = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxJacobian, kMaxJacobian>;
using VectorJ = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxJacobian, 1>;

// One pass's sums over the reference level, in double.
struct ReduceSums {
  MatrixJ JtWJ;      // nj x nj, symmetric (both triangles filled)
  VectorJ JtWr;      // nj
  double cost = 0;   // sum of Huber costs rho(r)
  double wrr = 0;    // sum of weight * r^2
  double valid = 0;  // pixels with a valid reference and a valid live sample
  double inlier = 0; // of those, |r| <= k
  double ref = 0;    // pixels with a valid reference
  // Cluster-robust outer product of the scores (nj x nj), for a covariance that does not take
  // neighbouring pixels' residuals as independent: the valid pixels are grouped into clusters
  // of whole work-groups (WarpReduceOptions::cluster_width, cluster_bands), each
  // cluster's score s_c = sum of J w r over its pixels is extrapolated to the Gauss-Newton
  // solution of this pass's own sums (s_c + (J^T W J)_c delta, delta = -(J^T W J)^-1 J^T W r, all
  // nj parameters; the extrapolated scores sum to zero), and score_outer = sum_c s_c s_c^T over
  // the `clusters` clusters with valid pixels. Filled by WarpReduce::run and the reference,
  // not by assign().
  MatrixJ score_outer;
  double clusters = 0;
  // The STATS variant's (zero otherwise):
  bool has_stats = false;
  double rr = 0;                // sum of r^2
  double iref = 0, iref2 = 0;   // sums of (I_r - 128) and its square over the valid pixels
  double glive = 0, gref = 0;   // sums of |grad I_l(w(p))|^2 and |grad I_r(p)|^2 over them
  int hist_bins = 0;
  // Over a subsample of the valid pixels (each work-item's first pixel), hist_valid of them:
  double hist_valid = 0;
  std::array<double, kMaxHistBins> hist{};  // counts of |r| < ReduceLayout::hist_threshold(j)
  // J^T J over the inliers (|r| <= k), unweighted: the Huber cost's own Hessian (psi' is 1
  // inside the threshold and 0 beyond), where J^T W J is the reweighted one.
  MatrixJ JtJ_inlier;

  // Fills the fields from the summed row (layout.count() values).
  void assign(const ReduceLayout& layout, const double* row);
  // Median of |r| over the histogram's subsample from the cumulative histogram, interpolated linearly
  // in log |r| between the bins' thresholds; the last threshold when more than half of the
  // residuals lie beyond it, and the first (halved) when more than half lie below it.
  double median_abs_residual() const;
};

// What one pass needs besides the images.
struct WarpInputs {
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();  // reference -> live pixels
  int nparam = 3;
  std::array<Eigen::Matrix3d, kMaxParams> G{};  // reference-side generators (warp_model.h)
  double gain = 1.0, bias = 0.0;                // e^a and b
  double huber_k = 1e30;                        // Huber threshold, grey levels (> 0)
};

// A host float4 level (pyramid.h's layout), stride in float4 elements.
struct LevelView {
  const float* data = nullptr;
  int width = 0, height = 0, stride = 0;
};

// The kernels' warp of reference pixel (u, v) into a live level, in float in their order (so that
// a reference decides validity as its kernel does), and the bilinear sample there, valid only when
// all four neighbours lie inside and are valid: the part of kernels/track/warp_reduce.cl and
// kernels/track/motion_search.cl that their plain C++ references share.
struct KernelSample {
  float qz = 0, wu = 0, wv = 0;  // q = H (u, v, 1); w = (q.x, q.y) / q.z (clamped to +-1e6)
  double value[3] = {0, 0, 0};   // the live level's (I, dI/du, dI/dv) at w, bilinear, in double
};
// False (and *out unspecified) where the sample is not valid. h: H row by row, as the kernels get it.
bool kernel_sample(const float h[9], int u, int v, const LevelView& live, KernelSample* out);

struct WarpReduceOptions;

// The plain C++ reference of the kernel: the same per-pixel formulas, the warp in float in the
// kernel's order (so validity decisions match), everything after it in double, accumulated in
// double. Returns the sums for the layout's nparam, stats and hist_bins; the histogram's
// subsample is the pixels whose column c satisfies (c mod (wg_x * pix)) < wg_x, as the
// kernel's work distribution makes it; the score clusters are those of WarpReduce::run with
// the options' work-group shape and cluster size (the first form: wg_y = 1, default clusters).
ReduceSums warp_reduce_reference(const LevelView& ref, const LevelView& live,
                                 const WarpInputs& in, const ReduceLayout& layout, int wg_x = 16,
                                 int pixels_per_item = 8);
ReduceSums warp_reduce_reference(const LevelView& ref, const LevelView& live,
                                 const WarpInputs& in, const ReduceLayout& layout,
                                 const WarpReduceOptions& options);

struct WarpReduceOptions {
  int wg_x = 16, wg_y = 1;   // work-group shape (WG_X x WG_Y must be a power of two)
  int pixels_per_item = 8;   // PIX: pixels per work-item along a row, WG_X apart
  int lanes = 8;             // LANES: 8 pixels at a time as float8 (pixels_per_item a multiple of 8), or 1
  bool stats = false;        // the STATS variant: residual, intensity and gradient statistics
  int hist_bins = 16;        // and a histogram of |r| for the robust scale (with stats only)
  bool fast_math = false;    // -cl-fast-relaxed-math (no faster on PoCL: src/track/README.md)
  bool debug_output = false; // per-pixel (r, weight, valid, rho) into a debug buffer
  // 0: the reference is a level; B > 0: it is a level's subsampled pixels, one per B x B block
  // (pixel_selection.h), and ref_w x ref_h is their grid's size (the SELECT variant, one
  // program for every B, which is its argument).
  int select_block = 0;
  // The clusters of ReduceSums::score_outer: whole work-groups, as many side by side as come
  // nearest cluster_width pixels, and as many rows of them as come nearest 1 / cluster_bands of
  // the level's height (a fixed share of the view, so a fixed patch of ground at every level and
  // image size: 128 x 60 pixels at 640 x 480, 128 x 30 at 320 x 240; measured in
  // test/bench/results/track.md, "Covariance (simulator)").
  int cluster_width = 128, cluster_bands = 8;
};

// The pass on the device. Builds its program once; run() allocates nothing once the partials
// buffer has grown to the largest level it has seen.
class WarpReduce {
 public:
  WarpReduce(ocl::Runtime& runtime, int nparam, const WarpReduceOptions& options = {});

  // Enqueues the pass for a reference level and a live level (float4 buffers of pyramid.h,
  // stride == width), reads the partials back (the one blocking call) and sums them in double
  // into *out. With debug_output, `debug` (ref_w * ref_h float4) receives the per-pixel values.
  void run(const cl::Buffer& ref, int ref_w, int ref_h, const cl::Buffer& live, int live_w,
           int live_h, const WarpInputs& in, ReduceSums* out, cl::Buffer* debug = nullptr);

  const ReduceLayout& layout() const { return layout_; }
  const std::string& build_options() const { return build_options_; }
  static std::string build_options(int nparam, const WarpReduceOptions& options);

 private:
  ocl::Runtime& runtime_;
  WarpReduceOptions options_;
  ReduceLayout layout_;
  std::string build_options_;
  cl::Kernel kernel_;
  cl::Buffer params_;
  cl::Buffer partials_;
  size_t partials_capacity_ = 0;  // floats
  std::vector<float> params_host_;
  std::vector<float> partials_host_;
  std::vector<double> row_;
  std::vector<double> clusters_;  // per score cluster: J^T W r, J^T W J, valid
};

}  // namespace planarvo::track
