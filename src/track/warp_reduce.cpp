#include "track/warp_reduce.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>

#include "core/error.h"
#include "ocl/runtime.h"

namespace planarvo::track {

double ReduceLayout::hist_threshold(int j) { return 0.25 * std::pow(2.0, 0.5 * j); }

namespace {

// The score clusters: whole work-groups, merge_x side by side and merge_y rows of them.
struct ClusterGrid {
  size_t span = 1, wg_y = 1;        // pixels of one work-group along x, y
  size_t groups_x = 0, groups_y = 0;
  size_t merge_x = 1, merge_y = 1;  // work-groups per cluster along x, y
  size_t clusters_x = 0, clusters_y = 0;

  ClusterGrid(int width, int height, int wg_x, int wg_y_, int pix, int cluster_width, int cluster_bands) {
    span = static_cast<size_t>(wg_x) * static_cast<size_t>(pix);
    wg_y = static_cast<size_t>(wg_y_);
    groups_x = (static_cast<size_t>(width) + span - 1) / span;
    groups_y = (static_cast<size_t>(height) + wg_y - 1) / wg_y;
    const size_t bands = static_cast<size_t>(std::max(1, cluster_bands));
    const size_t band_rows = (static_cast<size_t>(std::max(1, height)) + bands - 1) / bands;
    merge_x = std::max<size_t>(1, (static_cast<size_t>(std::max(0, cluster_width)) + span / 2) / span);
    merge_y = std::max<size_t>(1, (band_rows + wg_y / 2) / wg_y);
    clusters_x = (groups_x + merge_x - 1) / merge_x;
    clusters_y = (groups_y + merge_y - 1) / merge_y;
  }
  size_t clusters() const { return clusters_x * clusters_y; }
  size_t of_group(size_t gx, size_t gy) const { return (gy / merge_y) * clusters_x + gx / merge_x; }
  size_t of_pixel(int x, int y) const { return of_group(static_cast<size_t>(x) / span, static_cast<size_t>(y) / wg_y); }
};

// Per cluster: J^T W r (nj), the upper triangle of J^T W J (nh, ReduceLayout's order), valid.
size_t cluster_stride(const ReduceLayout& L) { return static_cast<size_t>(L.nj() + L.nh() + 1); }

// score_outer and clusters from the per-cluster sums (ReduceSums::score_outer).
void finish_score_outer(const ReduceLayout& L, const std::vector<double>& acc, ReduceSums* out) {
  const int nj = L.nj();
  VectorJ delta = VectorJ::Zero(nj);
  const Eigen::LDLT<MatrixJ> ldlt(out->JtWJ);
  if (ldlt.info() == Eigen::Success) delta = -ldlt.solve(out->JtWr);
  if (!delta.allFinite()) delta.setZero();
  out->score_outer = MatrixJ::Zero(nj, nj);
  out->clusters = 0;
  const size_t stride = cluster_stride(L);
  VectorJ sc(nj);
  for (size_t c = 0; c + stride <= acc.size(); c += stride) {
    const double* a = &acc[c];
    if (!(a[stride - 1] > 0)) continue;
    for (int i = 0; i < nj; ++i) {
      double v = a[i];
      for (int j = 0; j < nj; ++j) v += a[nj + L.jtj(std::min(i, j), std::max(i, j))] * delta(j);
      sc(i) = v;
    }
    out->score_outer.noalias() += sc * sc.transpose();
    out->clusters += 1;
  }
}

}  // namespace

void ReduceSums::assign(const ReduceLayout& L, const double* row) {
  const int n = L.nj();
  JtWJ.resize(n, n);
  JtWr.resize(n);
  score_outer = MatrixJ::Zero(n, n);
  clusters = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < n; ++j) JtWJ(i, j) = JtWJ(j, i) = row[L.jtj(i, j)];
    JtWr(i) = row[L.jtr(i)];
  }
  cost = row[L.cost()];
  wrr = row[L.wrr()];
  valid = row[L.valid()];
  inlier = row[L.inlier()];
  ref = row[L.ref()];
  has_stats = L.stats;
  rr = iref = iref2 = glive = gref = hist_valid = 0.0;
  hist_bins = L.stats ? L.hist_bins : 0;
  hist.fill(0.0);
  JtJ_inlier.resize(0, 0);
  if (!L.stats) return;
  rr = row[L.rr()];
  iref = row[L.iref()];
  iref2 = row[L.iref2()];
  glive = row[L.glive()];
  gref = row[L.gref()];
  hist_valid = row[L.hvalid()];
  for (int j = 0; j < L.hist_bins; ++j) hist[static_cast<size_t>(j)] = row[L.hist(j)];
  JtJ_inlier.resize(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = i; j < n; ++j) JtJ_inlier(i, j) = JtJ_inlier(j, i) = row[L.jtj_inlier(i, j)];
}

double ReduceSums::median_abs_residual() const {
  if (hist_bins <= 0 || !(hist_valid > 0)) return std::nan("");
  const double half = 0.5 * hist_valid;
  if (hist[0] >= half) return 0.5 * ReduceLayout::hist_threshold(0);
  for (int j = 1; j < hist_bins; ++j) {
    const double c1 = hist[static_cast<size_t>(j)];
    if (c1 >= half) {
      const double c0 = hist[static_cast<size_t>(j - 1)];
      const double f = c1 > c0 ? (half - c0) / (c1 - c0) : 0.0;
      const double t0 = ReduceLayout::hist_threshold(j - 1);
      const double t1 = ReduceLayout::hist_threshold(j);
      return t0 * std::pow(t1 / t0, f);
    }
  }
  return ReduceLayout::hist_threshold(hist_bins - 1);
}

bool kernel_sample(const float h[9], int u, int v, const LevelView& live, KernelSample* out) {
  const float fu = static_cast<float>(u), fv = static_cast<float>(v);
  const float qx = h[0] * fu + h[1] * fv + h[2];
  const float qy = h[3] * fu + h[4] * fv + h[5];
  const float qz = h[6] * fu + h[7] * fv + h[8];
  if (!(qz > 1e-12f)) return false;
  const float iz = 1.0f / qz;
  const float wu = std::clamp(qx * iz, -1e6f, 1e6f), wv = std::clamp(qy * iz, -1e6f, 1e6f);
  const float bu = std::floor(wu), bv = std::floor(wv);
  const int iu = static_cast<int>(bu), iv = static_cast<int>(bv);
  if (iu < 0 || iv < 0 || iu >= live.width - 1 || iv >= live.height - 1) return false;
  const float* s00 = live.data + 4 * (static_cast<size_t>(iv) * live.stride + iu);
  const float* s01 = s00 + 4;
  const float* s10 = s00 + 4 * static_cast<size_t>(live.stride);
  const float* s11 = s10 + 4;
  if (s00[3] == 0.0f || s01[3] == 0.0f || s10[3] == 0.0f || s11[3] == 0.0f) return false;
  const double ax = wu - bu, ay = wv - bv;
  for (int c = 0; c < 3; ++c)
    out->value[c] = (1 - ax) * (1 - ay) * s00[c] + ax * (1 - ay) * s01[c] + (1 - ax) * ay * s10[c] + ax * ay * s11[c];
  out->qz = qz;
  out->wu = wu;
  out->wv = wv;
  return true;
}

ReduceSums warp_reduce_reference(const LevelView& ref, const LevelView& live,
                                 const WarpInputs& in, const ReduceLayout& L, int wg_x,
                                 int pixels_per_item) {
  WarpReduceOptions o;
  o.wg_x = wg_x;
  o.wg_y = 1;
  o.pixels_per_item = pixels_per_item;
  return warp_reduce_reference(ref, live, in, L, o);
}

ReduceSums warp_reduce_reference(const LevelView& ref, const LevelView& live,
                                 const WarpInputs& in, const ReduceLayout& L,
                                 const WarpReduceOptions& o) {
  const int wg_x = o.wg_x;
  const int span = wg_x * o.pixels_per_item;
  const ClusterGrid grid(ref.width, ref.height, o.wg_x, o.wg_y, o.pixels_per_item, o.cluster_width,
                         o.cluster_bands);
  const size_t cstride = cluster_stride(L);
  std::vector<double> cl(grid.clusters() * cstride, 0.0);
  if (in.nparam != L.nparam) throw_invalid_argument("warp_reduce_reference: nparam mismatch");
  const int nj = L.nj();
  std::vector<double> row(static_cast<size_t>(L.count()), 0.0);
  float h[9];
  for (int i = 0; i < 9; ++i) h[i] = static_cast<float>(in.H(i / 3, i % 3));
  const float gain_f = static_cast<float>(in.gain);
  const double gain = gain_f, bias = static_cast<float>(in.bias);
  const double k = static_cast<float>(in.huber_k);
  std::array<double, kMaxJacobian> J{};
  std::array<double, kMaxHistBins> thr{};
  for (int j = 0; j < L.hist_bins; ++j) thr[static_cast<size_t>(j)] = static_cast<float>(ReduceLayout::hist_threshold(j));
  auto at = [](const LevelView& l, int x, int y) { return l.data + 4 * (static_cast<size_t>(y) * l.stride + x); };

  for (int y = 0; y < ref.height; ++y) {
    for (int x = 0; x < ref.width; ++x) {
      const float* R = at(ref, x, y);
      if (R[3] == 0.0f) continue;
      row[static_cast<size_t>(L.ref())] += 1.0;
      // The pixel: this one, or the block's chosen one (its code, kernels/track/select_pixels.cl).
      int px = x, py = y;
      if (o.select_block > 0) {
        const int off = static_cast<int>(R[3]) - 1;
        px = x * o.select_block + off % 256;
        py = y * o.select_block + off / 256;
      }
      KernelSample sample;
      if (!kernel_sample(h, px, py, live, &sample)) continue;
      const double* Ls = sample.value;
      const float qz = sample.qz, wu = sample.wu, wv = sample.wv;
      const double r = gain * Ls[0] + bias - R[0];
      const double dz = 1.0 / qz;
      const double d00 = dz * (h[0] - wu * h[6]), d01 = dz * (h[1] - wu * h[7]);
      const double d10 = dz * (h[3] - wv * h[6]), d11 = dz * (h[4] - wv * h[7]);
      const double gu = 0.5 * (R[1] + gain * (Ls[1] * d00 + Ls[2] * d10));
      const double gv = 0.5 * (R[2] + gain * (Ls[1] * d01 + Ls[2] * d11));
      const double u = px, v = py;
      for (int i = 0; i < L.nparam; ++i) {
        const Eigen::Matrix3d& G = in.G[static_cast<size_t>(i)];
        const double mx = G(0, 0) * u + G(0, 1) * v + G(0, 2);
        const double my = G(1, 0) * u + G(1, 1) * v + G(1, 2);
        const double mz = G(2, 0) * u + G(2, 1) * v + G(2, 2);
        J[static_cast<size_t>(i)] = gu * (mx - u * mz) + gv * (my - v * mz);
      }
      J[static_cast<size_t>(L.nparam)] = gain * Ls[0];
      J[static_cast<size_t>(L.nparam + 1)] = 1.0;
      const double ar = std::abs(r);
      const bool inlier = ar <= k;
      const double w = inlier ? 1.0 : k / ar;
      const double rho = inlier ? 0.5 * r * r : k * (ar - 0.5 * k);
      double* c = &cl[grid.of_pixel(x, y) * cstride];
      for (int i = 0; i < nj; ++i) {
        for (int j = i; j < nj; ++j) {
          row[static_cast<size_t>(L.jtj(i, j))] += w * J[static_cast<size_t>(i)] * J[static_cast<size_t>(j)];
          c[nj + L.jtj(i, j)] += w * J[static_cast<size_t>(i)] * J[static_cast<size_t>(j)];
        }
        row[static_cast<size_t>(L.jtr(i))] += w * J[static_cast<size_t>(i)] * r;
        c[i] += w * J[static_cast<size_t>(i)] * r;
      }
      c[cstride - 1] += 1.0;
      row[static_cast<size_t>(L.cost())] += rho;
      row[static_cast<size_t>(L.wrr())] += w * r * r;
      row[static_cast<size_t>(L.valid())] += 1.0;
      row[static_cast<size_t>(L.inlier())] += inlier ? 1.0 : 0.0;
      if (!L.stats) continue;
      row[static_cast<size_t>(L.rr())] += r * r;
      const double ic = R[0] - 128.0;
      row[static_cast<size_t>(L.iref())] += ic;
      row[static_cast<size_t>(L.iref2())] += ic * ic;
      row[static_cast<size_t>(L.glive())] += Ls[1] * Ls[1] + Ls[2] * Ls[2];
      row[static_cast<size_t>(L.gref())] += static_cast<double>(R[1]) * R[1] + static_cast<double>(R[2]) * R[2];
      if (inlier)
        for (int i = 0; i < nj; ++i)
          for (int j = i; j < nj; ++j)
            row[static_cast<size_t>(L.jtj_inlier(i, j))] += J[static_cast<size_t>(i)] * J[static_cast<size_t>(j)];
      if (x % span >= wg_x) continue;
      row[static_cast<size_t>(L.hvalid())] += 1.0;
      for (int j = 0; j < L.hist_bins; ++j)
        row[static_cast<size_t>(L.hist(j))] += ar < thr[static_cast<size_t>(j)] ? 1.0 : 0.0;
    }
  }
  ReduceSums out;
  out.assign(L, row.data());
  finish_score_outer(L, cl, &out);
  return out;
}

std::string WarpReduce::build_options(int nparam, const WarpReduceOptions& o) {
  std::ostringstream s;
  s << "-D NPARAM=" << nparam << " -D WG_X=" << o.wg_x << " -D WG_Y=" << o.wg_y
    << " -D PIX=" << o.pixels_per_item << " -D LANES=" << o.lanes;
  if (o.stats) s << " -D STATS=1 -D HIST_BINS=" << o.hist_bins;
  if (o.select_block > 0) s << " -D SELECT=1";  // the block size is an argument
  if (o.debug_output) s << " -D DEBUG_OUTPUT";
  if (o.fast_math) s << " -cl-fast-relaxed-math";
  return s.str();
}

WarpReduce::WarpReduce(ocl::Runtime& runtime, int nparam, const WarpReduceOptions& options)
    : runtime_(runtime), options_(options) {
  if (nparam < 1 || nparam > kMaxParams)
    throw_invalid_argument("WarpReduce: nparam must be 1.." + std::to_string(kMaxParams));
  const int wg = options.wg_x * options.wg_y;
  if (options.wg_x < 1 || options.wg_y < 1 || (wg & (wg - 1)) != 0)
    throw_invalid_argument("WarpReduce: the work-group size wg_x * wg_y must be a power of two");
  if (options.pixels_per_item < 1 || options.pixels_per_item > 64)
    throw_invalid_argument("WarpReduce: pixels_per_item must be 1..64");
  if ((options.lanes != 1 && options.lanes != 8) || options.pixels_per_item % options.lanes != 0)
    throw_invalid_argument("WarpReduce: lanes must be 1 or 8, and divide pixels_per_item");
  if (options.select_block < 0 || options.select_block > 64)
    throw_invalid_argument("WarpReduce: select_block must be 0..64");
  if (options.hist_bins < 0 || options.hist_bins > kMaxHistBins)
    throw_invalid_argument("WarpReduce: hist_bins must be 0.." + std::to_string(kMaxHistBins));
  layout_.nparam = nparam;
  layout_.stats = options.stats;
  layout_.hist_bins = options.stats ? options.hist_bins : 0;
  build_options_ = build_options(nparam, options);
  ocl::Runtime::register_build_options("warp_reduce", build_options_);
  kernel_ = cl::Kernel(runtime.program("warp_reduce", build_options_), "warp_reduce");
  params_host_.assign(static_cast<size_t>(9 * (nparam + 1)), 0.0f);
  params_ = cl::Buffer(runtime.context(), CL_MEM_READ_ONLY, params_host_.size() * sizeof(float));
  row_.assign(static_cast<size_t>(layout_.count()), 0.0);
}

void WarpReduce::run(const cl::Buffer& ref, int ref_w, int ref_h, const cl::Buffer& live,
                     int live_w, int live_h, const WarpInputs& in, ReduceSums* out,
                     cl::Buffer* debug) {
  if (in.nparam != layout_.nparam) throw_invalid_argument("WarpReduce::run: nparam mismatch");
  if (ref_w < 1 || ref_h < 1 || live_w < 2 || live_h < 2)
    throw_invalid_argument("WarpReduce::run: levels must be at least 1x1 (reference) and 2x2 (live)");
  if (options_.debug_output != (debug != nullptr))
    throw_invalid_argument("WarpReduce::run: a debug buffer goes with debug_output, and only then");
  for (int i = 0; i < 9; ++i) params_host_[static_cast<size_t>(i)] = static_cast<float>(in.H(i / 3, i % 3));
  for (int p = 0; p < in.nparam; ++p)
    for (int i = 0; i < 9; ++i)
      params_host_[static_cast<size_t>(9 + 9 * p + i)] =
          static_cast<float>(in.G[static_cast<size_t>(p)](i / 3, i % 3));

  const size_t wx = static_cast<size_t>(options_.wg_x), wy = static_cast<size_t>(options_.wg_y);
  const size_t span = wx * static_cast<size_t>(options_.pixels_per_item);
  const size_t groups_x = (static_cast<size_t>(ref_w) + span - 1) / span;
  const size_t groups_y = (static_cast<size_t>(ref_h) + wy - 1) / wy;
  const size_t groups = groups_x * groups_y;
  const size_t n = groups * static_cast<size_t>(layout_.count());
  if (n > partials_capacity_) {
    partials_ = cl::Buffer(runtime_.context(), CL_MEM_WRITE_ONLY | CL_MEM_ALLOC_HOST_PTR, n * sizeof(float));
    partials_capacity_ = n;
    partials_host_.resize(n);
  }

  cl::CommandQueue& q = runtime_.queue();
  q.enqueueWriteBuffer(params_, CL_FALSE, 0, params_host_.size() * sizeof(float), params_host_.data());
  int a = 0;
  kernel_.setArg(a++, ref);
  kernel_.setArg(a++, ref_w);  // stride
  kernel_.setArg(a++, ref_w);
  kernel_.setArg(a++, ref_h);
  kernel_.setArg(a++, live);
  kernel_.setArg(a++, live_w);  // stride
  kernel_.setArg(a++, live_w);
  kernel_.setArg(a++, live_h);
  kernel_.setArg(a++, params_);
  kernel_.setArg(a++, static_cast<float>(in.gain));
  kernel_.setArg(a++, static_cast<float>(in.bias));
  kernel_.setArg(a++, static_cast<float>(in.huber_k));
  if (options_.select_block > 0) kernel_.setArg(a++, static_cast<cl_int>(options_.select_block));
  kernel_.setArg(a++, partials_);
  if (debug) kernel_.setArg(a++, *debug);
  q.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(groups_x * wx, groups_y * wy),
                         cl::NDRange(wx, wy));
  q.enqueueReadBuffer(partials_, CL_TRUE, 0, n * sizeof(float), partials_host_.data());

  const size_t c = static_cast<size_t>(layout_.count());
  std::fill(row_.begin(), row_.end(), 0.0);
  const float* p = partials_host_.data();
  for (size_t g = 0; g < groups; ++g, p += c)
    for (size_t o = 0; o < c; ++o) row_[o] += static_cast<double>(p[o]);
  out->assign(layout_, row_.data());

  // The score clusters from the same rows (a few additions per work-group).
  const ClusterGrid grid(ref_w, ref_h, options_.wg_x, options_.wg_y, options_.pixels_per_item,
                         options_.cluster_width, options_.cluster_bands);
  const int nj = layout_.nj(), nh = layout_.nh();
  const size_t cstride = cluster_stride(layout_);
  clusters_.assign(grid.clusters() * cstride, 0.0);
  p = partials_host_.data();
  for (size_t gy = 0; gy < groups_y; ++gy)
    for (size_t gx = 0; gx < groups_x; ++gx, p += c) {
      double* cs = &clusters_[grid.of_group(gx, gy) * cstride];
      for (int i = 0; i < nj; ++i) cs[i] += static_cast<double>(p[layout_.jtr(i)]);
      for (int i = 0; i < nh; ++i) cs[nj + i] += static_cast<double>(p[layout_.jtj(0, 0) + i]);
      cs[cstride - 1] += static_cast<double>(p[layout_.valid()]);
    }
  finish_score_outer(layout_, clusters_, out);
}

}  // namespace planarvo::track
