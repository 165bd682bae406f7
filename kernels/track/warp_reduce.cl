// The tracker's fused pass (paper section 4, eqs. 5-13): for every valid pixel p of a reference
// pyramid level, warp it into the live level through the homography H, sample the live level
// bilinearly, form the photometric residual with an affine brightness model, its ESM Jacobian,
// a Huber weight, and reduce J^T W J, J^T W r, the cost and counts into one row of partial sums
// per work-group (local-memory tree reduction; the host sums the rows in 64-bit precision). The layout
// of a row is mirrored by src/track/warp_reduce.h (ReduceLayout); the plain C++ reference is
// warp_reduce_reference() in src/track/warp_reduce.cpp.
//
// Per pixel p = (u, v) with reference sample R = ref(p) = (I_r, dI_r/du, dI_r/dv, valid):
//   q = H (u, v, 1); w(p) = (q.x / q.z, q.y / q.z)
//   L = bilinear sample of the live level at w(p) (intensity and gradient), valid only when
//       all four neighbours are inside and valid
//   r = gain * I_l(w(p)) + bias - I_r(p)          (gain = e^a: brightness (a, b), r of eq. 7)
//   gradient in reference coordinates, the ESM mean of the reference gradient and the warped
//   live gradient chained through the warp's 2x2 derivative Dw = ∂π/∂h|q H[:, 0:2] (eq. 11):
//       g = 0.5 * (∇I_r(p) + gain * ∇I_l(w(p)) Dw)
//   J_i = g . (m_i.x, m_i.y),  m_i = ∂π/∂h|(u,v,1) G_i (u, v, 1), i < NPARAM              (eq. 12)
//       G_i = H^-1 ∂H/∂x_i, the derivative of the warp on the reference side (warp_model.h)
//   J_NPARAM = gain * I_l(w(p))  (∂r/∂a),  J_NPARAM+1 = 1  (∂r/∂b)
//   Huber: weight = min(1, k / |r|), cost rho = r^2 / 2 or k (|r| - k / 2).
//
// Work distribution: 2-D range; a work-group is WG_X x WG_Y work-items, each handles PIX pixels
// of one row: with LANES 1 one at a time, WG_X apart (neighbouring work-items read neighbouring
// pixels); with LANES 8 (the default) as runs of 8 consecutive pixels, WG_X * 8 apart. Global size: (ceil(width / (WG_X PIX)) WG_X, ceil(height / WG_Y)
// WG_Y); pixels beyond the level are masked out. Row g of the partials belongs to work-group
// (group_id(0) + num_groups(0) * group_id(1)).
//
// Build options (-D): NPARAM (3), WG_X (16), WG_Y (1), PIX (8), LANES (8: a work-item's pixels
// eight at a time as float8, below; 1: one at a time, the form above), STATS (0: 1 adds the
// statistics below, a histogram of HIST_BINS (16) bins of |r| and J^T J over the inliers),
// SELECT (0: see below), DEBUG_OUTPUT (off: when defined, a last argument receives per
// reference pixel (r, weight, valid, rho); not for the fast path).
//
// With SELECT = 1 the reference is not a level but its subsampled pixels
// (kernels/track/select_pixels.cl) and an argument select_block = B follows huber_k: a grid of
// ref_w x ref_h entries, one per B x B block of the level, each (I_r, dI_r/du, dI_r/dv, code) of
// the block's pixel, code = 1 + ox + 256 oy for the pixel (bx B + ox, by B + oy) of block (bx, by),
// 0 for none. Everything above then applies to that pixel; the work distribution, the partials
// and the clusters are those of the grid. B is an argument, not a build option, so that one
// program serves every block size.
#ifndef NPARAM
#define NPARAM 3
#endif
#ifndef WG_X
#define WG_X 16
#endif
#ifndef WG_Y
#define WG_Y 1
#endif
#ifndef PIX
#define PIX 8
#endif
#ifndef STATS
#define STATS 0
#endif
#ifndef HIST_BINS
#define HIST_BINS 16
#endif
#ifndef SELECT
#define SELECT 0
#endif
#ifndef LANES
#define LANES 8
#endif
#if LANES != 1 && LANES != 8
#error "warp_reduce: LANES must be 1 or 8"
#endif
#if LANES == 8 && PIX % 8
#error "warp_reduce: with LANES 8, PIX must be a multiple of 8"
#endif

#if (WG_X * WG_Y) & (WG_X * WG_Y - 1)
#error "warp_reduce: WG_X * WG_Y must be a power of two (tree reduction)"
#endif

#define NJ (NPARAM + 2)
#define NH PV_REDUCE_NH(NJ)
#define WG (WG_X * WG_Y)
// Row layout: kernels/track/warp_reduce_layout.h, which ReduceLayout (warp_reduce.h) reads by.
// The statistics after OUT_REF are only in the STATS variant, which the tracker runs once per
// level: each extra sum costs every pixel. The histogram counts only each work-item's first
// pixel (one in PIX).
#include "kernels/track/warp_reduce_layout.h"
#define OUT_JTJ PV_REDUCE_JTJ
#define OUT_JTR PV_REDUCE_JTR(NJ)
#define OUT_COST PV_REDUCE_COST(NJ)
#define OUT_WRR PV_REDUCE_WRR(NJ)
#define OUT_VALID PV_REDUCE_VALID(NJ)
#define OUT_INLIER PV_REDUCE_INLIER(NJ)
#define OUT_REF PV_REDUCE_REF(NJ)
#if STATS
#define OUT_RR PV_REDUCE_RR(NJ)
#define OUT_IREF PV_REDUCE_IREF(NJ)
#define OUT_IREF2 PV_REDUCE_IREF2(NJ)
#define OUT_GLIVE PV_REDUCE_GLIVE(NJ)
#define OUT_GREF PV_REDUCE_GREF(NJ)
#define OUT_HVALID PV_REDUCE_HVALID(NJ)
#define OUT_HIST PV_REDUCE_HIST(NJ)
#define OUT_JTJ_IN PV_REDUCE_JTJ_IN(NJ, HIST_BINS)
#define NOUT PV_REDUCE_STATS_COUNT(NJ, HIST_BINS)
#else
#define NOUT PV_REDUCE_PLAIN_COUNT(NJ)
#endif

// The sample of the live level at (x, y): all four neighbours must lie inside and be valid.
// Coordinates are clamped before the conversion to int (a NaN or huge value is then simply
// outside) and the addresses are clamped, so nothing is read out of bounds.
#define SAMPLE_CLAMP 1.0e6f

// The per-pixel algebra after the sample, shared by both forms: T is float (LANES 1) or float8
// (LANES 8), IT the matching int type (comparisons give 1 or -1 in it, which select() takes
// alike). Expects in scope: m (the pair's mask), lI, lGu, lGv (the live sample), rI, rGu, rGv,
// mref (the reference entry), fu, fv (the reference pixel), iz, wu, wv (the warp), h0..h8,
// params, gain, bias, huber_k and acc[NOUT] of T. Declares r, J, ar, inlier, wgt and rho.
#define WR_PIXEL_SUMS(T, IT)                                                                    \
  /* Residual with brightness (eq. 7). */                                                       \
  const T r = m * (gain * lI + bias - rI);                                                      \
  /* ESM gradient in reference coordinates (eq. 11): the live gradient through Dw. */           \
  const T d00 = iz * (h0 - wu * h6), d01 = iz * (h1 - wu * h7);                                 \
  const T d10 = iz * (h3 - wv * h6), d11 = iz * (h4 - wv * h7);                                 \
  const T gu = 0.5f * (rGu + gain * (lGu * d00 + lGv * d10));                                   \
  const T gv = 0.5f * (rGv + gain * (lGu * d01 + lGv * d11));                                   \
  /* Jacobian (eq. 12), zero where masked. */                                                   \
  T J[NJ];                                                                                      \
  _Pragma("unroll") for (int i = 0; i < NPARAM; ++i) {                                          \
    __constant const float* G = params + 9 + 9 * i;                                             \
    const T mx = G[0] * fu + G[1] * fv + G[2];                                                  \
    const T my = G[3] * fu + G[4] * fv + G[5];                                                  \
    const T mz = G[6] * fu + G[7] * fv + G[8];                                                  \
    J[i] = m * (gu * (mx - fu * mz) + gv * (my - fv * mz));                                     \
  }                                                                                             \
  J[NPARAM] = m * gain * lI;                                                                    \
  J[NPARAM + 1] = m;                                                                            \
  /* Huber weight and cost (a masked pixel has r = 0, an inlier). */                            \
  const T ar = fabs(r);                                                                         \
  const IT inlier = ar <= huber_k;                                                              \
  const T wgt = m * select(huber_k / ar, (T)(1.0f), inlier);                                    \
  const T rho = m * select(huber_k * (ar - 0.5f * huber_k), 0.5f * r * r, inlier);              \
  {                                                                                             \
    int o = 0;                                                                                  \
    _Pragma("unroll") for (int i = 0; i < NJ; ++i) {                                            \
      const T wj = wgt * J[i];                                                                  \
      _Pragma("unroll") for (int j = i; j < NJ; ++j) acc[o++] += wj * J[j];                     \
    }                                                                                           \
  }                                                                                             \
  _Pragma("unroll") for (int i = 0; i < NJ; ++i) acc[OUT_JTR + i] += wgt * J[i] * r;            \
  acc[OUT_COST] += rho;                                                                         \
  acc[OUT_WRR] += wgt * r * r;                                                                  \
  acc[OUT_VALID] += m;                                                                          \
  acc[OUT_INLIER] += select((T)(0.0f), m, inlier);                                              \
  acc[OUT_REF] += mref;                                                                         \
  WR_STATS_SUMS(T)

#if STATS
// The histogram's bin j counts |r| < 0.25 * 2^(j/2) (ReduceLayout::hist_threshold): exact
// powers of two for even j, times sqrt(2) for odd j.
float wr_hist_threshold(const int j) {
  return (j & 1) ? 0.35355339059327373f * (float)(1 << (j >> 1)) : 0.25f * (float)(1 << (j >> 1));
}

// The statistics' sums (the histogram is each form's own). The Huber cost's own Hessian
// (psi' = 1 inside k, 0 beyond) for the covariance: J^T J over the inliers, unweighted.
#define WR_STATS_SUMS(T)                                                                        \
  acc[OUT_RR] += r * r;                                                                         \
  {                                                                                             \
    const T ic = m * (rI - 128.0f);                                                             \
    acc[OUT_IREF] += ic;                                                                        \
    acc[OUT_IREF2] += ic * ic;                                                                  \
    acc[OUT_GLIVE] += m * (lGu * lGu + lGv * lGv);                                              \
    acc[OUT_GREF] += m * (rGu * rGu + rGv * rGv);                                               \
    const T win = select((T)(0.0f), m, inlier);                                                 \
    int oi = OUT_JTJ_IN;                                                                        \
    _Pragma("unroll") for (int i = 0; i < NJ; ++i) {                                            \
      const T wj = win * J[i];                                                                  \
      _Pragma("unroll") for (int j = i; j < NJ; ++j) acc[oi++] += wj * J[j];                    \
    }                                                                                           \
  }
#else
#define WR_STATS_SUMS(T)
#endif

// The kernel's arguments, one list for both forms (WarpReduce::run sets them by position):
// params holds H (9, row-major), then G_0 .. G_{NPARAM-1} (9 each).
#if SELECT
#define WR_SELECT_ARG const int select_block,
#else
#define WR_SELECT_ARG
#endif
#ifdef DEBUG_OUTPUT
#define WR_DEBUG_ARG , __global float4* debug
#else
#define WR_DEBUG_ARG
#endif
#define WR_KERNEL                                                                               \
  __kernel __attribute__((reqd_work_group_size(WG_X, WG_Y, 1))) void warp_reduce(               \
      __global const float4* ref, const int ref_stride, const int ref_w, const int ref_h,       \
      __global const float4* live, const int live_stride, const int live_w, const int live_h,   \
      __constant float* params, const float gain, const float bias, const float huber_k,        \
      WR_SELECT_ARG __global float* partials WR_DEBUG_ARG)

// The work-group's sums into its row of the partials: a tree reduction in local memory, one
// column of WG values per output.
void warp_reduce_store(const float* acc, __local float* scratch, __global float* partials) {
  const int lid = (int)get_local_id(1) * WG_X + (int)get_local_id(0);
#pragma unroll
  for (int o = 0; o < NOUT; ++o) scratch[o * WG + lid] = acc[o];
#pragma unroll
  for (int s = WG / 2; s > 0; s >>= 1) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lid < s) {
#pragma unroll
      for (int o = 0; o < NOUT; ++o) scratch[o * WG + lid] += scratch[o * WG + lid + s];
    }
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  const int group = (int)get_group_id(0) + (int)get_num_groups(0) * (int)get_group_id(1);
  for (int o = lid; o < NOUT; o += WG) partials[group * NOUT + o] = scratch[o * WG];
}

#if LANES == 8
// Eight pixels at a time. PoCL does not vectorise the per-pixel form below across work-items
// (its SLP pass first packs one pixel's arithmetic into short vectors, which stops the
// work-item-loop vectoriser, as in kernels/image/undistort.cl), so this form does it by hand: a
// work-item takes PIX pixels of a row as PIX / 8 runs of 8 consecutive pixels, the runs WG_X * 8
// apart, and every value below is a float8 of the run's pixels. Only the live level's four
// neighbours are gathered one pixel at a time (two vload8 each: the neighbours' (I, Gu, Gv, valid)
// on a row are 8 consecutive floats). A work-group covers the same WG_X * PIX pixels of a row as
// in the per-pixel form, so the partials, their clusters and the histogram's subsample (the first
// WG_X pixels of that span) are the same.

// M(k) for each lane k of a run.
#define WR_LANES(M) M(0) M(1) M(2) M(3) M(4) M(5) M(6) M(7)

float wr_sum8(const float8 v) {
  const float4 h = v.lo + v.hi;
  return (h.x + h.y) + (h.z + h.w);
}

WR_KERNEL {
  const int lx = (int)get_local_id(0);
  const int y = (int)get_global_id(1);
  const int x0 = (int)get_group_id(0) * (WG_X * PIX) + lx * 8;
  const int8 lane = (int8)(0, 1, 2, 3, 4, 5, 6, 7);

  float8 acc[NOUT];
#pragma unroll
  for (int o = 0; o < NOUT; ++o) acc[o] = (float8)(0.0f);
#if STATS
  float hist[HIST_BINS + 1];  // OUT_HVALID, then OUT_HIST (acc's entries for them stay 0)
#pragma unroll
  for (int j = 0; j <= HIST_BINS; ++j) hist[j] = 0.0f;
#endif

  __global const float* refp = (__global const float*)ref;
  __global const float* livep = (__global const float*)live;
  const float h0 = params[0], h1 = params[1], h2 = params[2];
  const float h3 = params[3], h4 = params[4], h5 = params[5];
  const float h6 = params[6], h7 = params[7], h8 = params[8];

  for (int k = 0; k < PIX / 8; ++k) {
    const int xs = x0 + k * (WG_X * 8);
    const int8 x = xs + lane;
    const int8 in_ref = y < ref_h ? (x < ref_w) : (int8)(0);
    // The run's reference entries: two float16 loads when the run lies inside the level, one
    // entry at a time (clamped, then masked) at a row's end.
    float8 rI, rGu, rGv, rC;
    if (y < ref_h && xs + 8 <= ref_w) {
      const float16 a = vload16(0, refp + 4 * (y * ref_stride + xs));
      const float16 b = vload16(0, refp + 4 * (y * ref_stride + xs) + 16);
      rI = (float8)(a.s048c, b.s048c);
      rGu = (float8)(a.s159d, b.s159d);
      rGv = (float8)(a.s26ae, b.s26ae);
      rC = (float8)(a.s37bf, b.s37bf);
    } else {
      const int yc = min(y, ref_h - 1);
#define WR_REF(j)                                                         \
  {                                                                       \
    const float4 e = ref[yc * ref_stride + min(xs + j, ref_w - 1)];       \
    rI.s##j = e.x; rGu.s##j = e.y; rGv.s##j = e.z; rC.s##j = e.w;         \
  }
      WR_LANES(WR_REF)
#undef WR_REF
      rC = select((float8)(0.0f), rC, in_ref);
    }
#if SELECT
    // The block's pixel (its code is a small integer, exact in float).
    const int8 code = convert_int8(rC);
    const int8 has = code > 0;
    const float8 mref = select((float8)(0.0f), (float8)(1.0f), has);
    const int8 off = select((int8)(0), code - 1, has);
    const float8 fu = convert_float8(x * select_block + (off & 255));
    const float8 fv = convert_float8(y * select_block + (off >> 8));
#else
    const float8 mref = rC;
    const float8 fu = convert_float8(x);
    const float8 fv = (float8)((float)y);
#endif

    // Warp (eq. 5): q = H p.
    const float8 qx = h0 * fu + h1 * fv + h2;
    const float8 qy = h3 * fu + h4 * fv + h5;
    const float8 qz = h6 * fu + h7 * fv + h8;
    const int8 front = qz > 1e-12f;
    const float8 iz = select((float8)(0.0f), 1.0f / qz, front);
    const float8 wu = clamp(qx * iz, -SAMPLE_CLAMP, SAMPLE_CLAMP);
    const float8 wv = clamp(qy * iz, -SAMPLE_CLAMP, SAMPLE_CLAMP);
    const float8 bu = floor(wu), bv = floor(wv);
    const int8 iu = convert_int8(bu), iv = convert_int8(bv);
    const int8 inside = front & (iu >= 0) & (iv >= 0) & (iu < live_w - 1) & (iv < live_h - 1);
    const int8 b00 = select((int8)(0), 4 * (iv * live_stride + iu), inside);
    const float8 ax = wu - bu, ay = wv - bv;
    const float8 w00 = (1.0f - ax) * (1.0f - ay), w01 = ax * (1.0f - ay);
    const float8 w10 = (1.0f - ax) * ay, w11 = ax * ay;
    float8 lI, lGu, lGv, lV;
#define WR_SAMPLE(j)                                                                         \
  {                                                                                          \
    const float8 t = vload8(0, livep + b00.s##j);                                            \
    const float8 d = vload8(0, livep + b00.s##j + 4 * live_stride);                          \
    const float4 s = w00.s##j * t.lo + w01.s##j * t.hi + w10.s##j * d.lo + w11.s##j * d.hi; \
    lI.s##j = s.x; lGu.s##j = s.y; lGv.s##j = s.z;                                           \
    lV.s##j = t.s3 * t.s7 * d.s3 * d.s7;                                                     \
  }
    WR_LANES(WR_SAMPLE)
#undef WR_SAMPLE
    const float8 m = select((float8)(0.0f), mref * lV, inside);

    WR_PIXEL_SUMS(float8, int8)
#if STATS
    // The histogram's subsample: the first WG_X pixels of the work-group's span, counted into
    // scalars (a float8 accumulator each would not fit the registers).
    if (k == 0 && lx * 8 < WG_X) {
      const float8 hm = select((float8)(0.0f), m, lx * 8 + lane < WG_X);
      hist[0] += wr_sum8(hm);
#pragma unroll
      for (int j = 0; j < HIST_BINS; ++j) {
        hist[1 + j] += wr_sum8(select((float8)(0.0f), hm, ar < wr_hist_threshold(j)));
      }
    }
#endif
#ifdef DEBUG_OUTPUT
#define WR_DEBUG(j) \
  if (in_ref.s##j) debug[y * ref_w + x.s##j] = (float4)(r.s##j, wgt.s##j, m.s##j, rho.s##j);
    WR_LANES(WR_DEBUG)
#undef WR_DEBUG
#endif
  }

  float sums[NOUT];
#pragma unroll
  for (int o = 0; o < NOUT; ++o) sums[o] = wr_sum8(acc[o]);
#if STATS
#pragma unroll
  for (int j = 0; j <= HIST_BINS; ++j) sums[OUT_HVALID + j] += hist[j];
#endif
  __local float scratch[NOUT * WG];
  warp_reduce_store(sums, scratch, partials);
}

#else  // LANES == 1: one pixel at a time
WR_KERNEL {
  const int lx = (int)get_local_id(0);
  const int y = (int)get_global_id(1);
  const int x0 = (int)get_group_id(0) * (WG_X * PIX) + lx;

  float acc[NOUT];
#pragma unroll
  for (int o = 0; o < NOUT; ++o) acc[o] = 0.0f;

  // Levels are read as plain floats (4 per pixel): LLVM's loop vectorizer, which PoCL uses
  // across work-items, gives up on loops with vector-typed (float4) values.
  __global const float* refp = (__global const float*)ref;
  __global const float* livep = (__global const float*)live;
  const float h0 = params[0], h1 = params[1], h2 = params[2];
  const float h3 = params[3], h4 = params[4], h5 = params[5];
  const float h6 = params[6], h7 = params[7], h8 = params[8];

#pragma unroll
  for (int k = 0; k < PIX; ++k) {
    const int x = x0 + k * WG_X;
    const int in_ref = (x < ref_w) & (y < ref_h);
    const int ri = in_ref ? 4 * (y * ref_stride + x) : 0;
    const float rI = refp[ri], rGu = refp[ri + 1], rGv = refp[ri + 2];
#if SELECT
    // The block's pixel (its code is a small integer, exact in float).
    const int code = in_ref ? (int)refp[ri + 3] : 0;
    const float mref = code > 0 ? 1.0f : 0.0f;
    const int off = code > 0 ? code - 1 : 0;
    const float fu = (float)(x * select_block + (off & 255));
    const float fv = (float)(y * select_block + (off >> 8));
#else
    const float mref = in_ref ? refp[ri + 3] : 0.0f;
    const float fu = (float)x;
    const float fv = (float)y;
#endif

    // Warp (eq. 5): q = H p.
    const float qx = h0 * fu + h1 * fv + h2;
    const float qy = h3 * fu + h4 * fv + h5;
    const float qz = h6 * fu + h7 * fv + h8;
    const float iz = qz > 1e-12f ? 1.0f / qz : 0.0f;
    const float wu = clamp(qx * iz, -SAMPLE_CLAMP, SAMPLE_CLAMP);
    const float wv = clamp(qy * iz, -SAMPLE_CLAMP, SAMPLE_CLAMP);
    const float bu = floor(wu), bv = floor(wv);
    const int iu = (int)bu, iv = (int)bv;
    const int inside = (qz > 1e-12f) & (iu >= 0) & (iv >= 0) & (iu < live_w - 1) &
                       (iv < live_h - 1);
    const int b00 = inside ? 4 * (iv * live_stride + iu) : 0;
    const int b10 = b00 + 4 * live_stride;
    const float ax = wu - bu, ay = wv - bv;
    const float w00 = (1.0f - ax) * (1.0f - ay), w01 = ax * (1.0f - ay);
    const float w10 = (1.0f - ax) * ay, w11 = ax * ay;
    const float lI = w00 * livep[b00] + w01 * livep[b00 + 4] + w10 * livep[b10] + w11 * livep[b10 + 4];
    const float lGu = w00 * livep[b00 + 1] + w01 * livep[b00 + 5] + w10 * livep[b10 + 1] +
                      w11 * livep[b10 + 5];
    const float lGv = w00 * livep[b00 + 2] + w01 * livep[b00 + 6] + w10 * livep[b10 + 2] +
                      w11 * livep[b10 + 6];
    const float m = inside ? mref * livep[b00 + 3] * livep[b00 + 7] * livep[b10 + 3] *
                                 livep[b10 + 7]
                           : 0.0f;

    WR_PIXEL_SUMS(float, int)
#if STATS
    // The histogram of |r| for the robust scale: a subsample (each work-item's first pixel)
    // is plenty for a median and saves most of its cost.
    if (k == 0) {
      acc[OUT_HVALID] += m;
#pragma unroll
      for (int j = 0; j < HIST_BINS; ++j) {
        acc[OUT_HIST + j] += ar < wr_hist_threshold(j) ? m : 0.0f;
      }
    }
#endif
#ifdef DEBUG_OUTPUT
    if (in_ref) debug[y * ref_w + x] = (float4)(r, wgt, m, rho);
#endif
  }

  __local float scratch[NOUT * WG];
  warp_reduce_store(acc, scratch, partials);
}

#endif  // LANES
