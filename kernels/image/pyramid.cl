// The Gaussian pyramid and the gradients, the image pipeline's second and third stages
// (src/image/pipeline.h; plain C++ references: downsample_reference, gradient_reference).
//
// Intensity images (between stages): float, grey levels 0..255, PV_INVALID where not valid.
// PV_INVALID is so negative that any weighted sum with an invalid term of weight >= 1 is
// negative (sums of valid terms are at most 1024 x 255), so validity is the sign of the sum.
//
// Each work-item makes 8 consecutive pixels of a row with explicit float8 arithmetic: PoCL
// does not vectorise these kernels across work-items when written per pixel (see
// src/image/README.md for the measurements).

#ifndef PYRAMID_WG_X
#define PYRAMID_WG_X 16
#endif
#ifndef PYRAMID_WG_Y
#define PYRAMID_WG_Y 4
#endif

// PV_INVALID and pv_store_head come from kernels/common/common.cl.

// ---------------------------------------------------------------------------------------------
// Downsampling: level l (sw x sh) -> level l + 1 (dw x dh = ceil(sw / 2) x ceil(sh / 2)).
// Output (u, v) is the separable [1 5 10 10 5 1] / 32 binomial over level-l columns 2u - 2 ..
// 2u + 3 and rows 2v - 2 .. 2v + 3 (the 5-tap Gaussian [1 4 6 4 1] / 16 sampled at the pixel
// centre, (2u + 0.5, 2v + 0.5)), taps clamped to the edge, invalid if any tap is.

// The horizontal sums of 8 consecutive outputs from one source row r: source columns c .. c + 19
// (c = 2u - 2 of the first output), clamped to 0..xm.
inline float8 pv_row_sums(__global const float* r, const int c, const int xm) {
  float16 a;  // columns c .. c + 15
  float4 b;   // columns c + 16 .. c + 19
  if (c >= 0 && c + 19 <= xm) {
    a = vload16(0, r + c);
    b = vload4(0, r + c + 16);
  } else {
#define PV_AT(i) r[clamp(c + (i), 0, xm)]
    a = (float16)(PV_AT(0), PV_AT(1), PV_AT(2), PV_AT(3), PV_AT(4), PV_AT(5), PV_AT(6), PV_AT(7),
                  PV_AT(8), PV_AT(9), PV_AT(10), PV_AT(11), PV_AT(12), PV_AT(13), PV_AT(14),
                  PV_AT(15));
    b = (float4)(PV_AT(16), PV_AT(17), PV_AT(18), PV_AT(19));
#undef PV_AT
  }
  // Output k's taps are columns c + 2k + 0..5: even e_j / odd o_j columns c + 2(k + j) (+ 1).
  const float8 e0 = a.even, o0 = a.odd;
  const float8 e1 = (float8)(a.s2468, a.sACE, b.s0), o1 = (float8)(a.s3579, a.sBDF, b.s1);
  const float8 e2 = (float8)(a.s468A, a.sCE, b.s02), o2 = (float8)(a.s579B, a.sDF, b.s13);
  return (e0 + o2) + 5.0f * (o0 + e2) + 10.0f * (e1 + o1);
}

__kernel __attribute__((reqd_work_group_size(PYRAMID_WG_X, PYRAMID_WG_Y, 1)))
void downsample(__global const float* src, const int sw, const int sh, __global float* dst,
                const int dw, const int dh) {
  const int u = (int)get_global_id(0) * 8;
  const int v = (int)get_global_id(1);
  if (u >= dw || v >= dh) return;
  const int xm = sw - 1, ym = sh - 1, c = 2 * u - 2;
  const float8 h0 = pv_row_sums(src + clamp(2 * v - 2, 0, ym) * sw, c, xm);
  const float8 h1 = pv_row_sums(src + clamp(2 * v - 1, 0, ym) * sw, c, xm);
  const float8 h2 = pv_row_sums(src + min(2 * v, ym) * sw, c, xm);
  const float8 h3 = pv_row_sums(src + min(2 * v + 1, ym) * sw, c, xm);
  const float8 h4 = pv_row_sums(src + min(2 * v + 2, ym) * sw, c, xm);
  const float8 h5 = pv_row_sums(src + min(2 * v + 3, ym) * sw, c, xm);
  const float8 s = (h0 + h5) + 5.0f * (h1 + h4) + 10.0f * (h2 + h3);
  const float8 out = select((float8)(PV_INVALID), s * (1.0f / 1024.0f), s >= 0.0f);
  if (u + 8 <= dw)
    vstore8(out, 0, dst + v * dw + u);
  else
    pv_store_head(out, dst + v * dw + u, dw - u);
}

// ---------------------------------------------------------------------------------------------
// The prefilter: an intensity image (w x h) -> the same size, the separable 3-tap binomial
// [1 2 1] / 4 in x then y (a Gaussian of sigma about 0.7 px), taps clamped to the edge, invalid
// if any tap is. It damps the pixel noise that bilinear interpolation turns into a bias of the
// alignment (src/track/README.md, "The prefilter").

// Elements x - 1 .. x + 8 of a row of w pixels, clamped to 0..w-1: the taps of 8 outputs.
inline float8 pv_row3(__global const float* r, const int x, const int w) {
  float8 c;
  float l, rr;
  if (x >= 1 && x + 9 <= w) {
    c = vload8(0, r + x);
    l = r[x - 1];
    rr = r[x + 8];
  } else {
    const int xm = w - 1;
#define PV_AT(i) r[clamp(x + (i), 0, xm)]
    c = (float8)(PV_AT(0), PV_AT(1), PV_AT(2), PV_AT(3), PV_AT(4), PV_AT(5), PV_AT(6), PV_AT(7));
    l = PV_AT(-1);
    rr = PV_AT(8);
#undef PV_AT
  }
  const float8 left = (float8)(l, c.s0, c.s1, c.s2, c.s3, c.s4, c.s5, c.s6);
  const float8 right = (float8)(c.s1, c.s2, c.s3, c.s4, c.s5, c.s6, c.s7, rr);
  return (left + right) + 2.0f * c;
}

__kernel __attribute__((reqd_work_group_size(PYRAMID_WG_X, PYRAMID_WG_Y, 1)))
void smooth(__global const float* src, const int w, const int h, __global float* dst) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= w || y >= h) return;
  const int ym = h - 1;
  const float8 t = pv_row3(src + max(y - 1, 0) * w, x, w);
  const float8 c = pv_row3(src + y * w, x, w);
  const float8 b = pv_row3(src + min(y + 1, ym) * w, x, w);
  const float8 s = (t + b) + 2.0f * c;
  const float8 out = select((float8)(PV_INVALID), s * (1.0f / 16.0f), s >= 0.0f);
  if (x + 8 <= w)
    vstore8(out, 0, dst + y * w + x);
  else
    pv_store_head(out, dst + y * w + x, w - x);
}

// ---------------------------------------------------------------------------------------------
// Gradients: an intensity image (w x h) -> the level's float4 layout of pyramid.h,
// (I, (I(u+1) - I(u-1)) / 2, (I(v+1) - I(v-1)) / 2, 1), or all 0 where the pixel or one of its
// four neighbours is invalid or outside the image.

// Elements x .. x + 7 of a row of w pixels; PV_INVALID outside 0..w-1.
inline float pv_at(__global const float* row, const int x, const int w) {
  return x >= 0 && x < w ? row[x] : PV_INVALID;
}
inline float8 pv_load8(__global const float* row, const int x, const int w) {
  if (x >= 0 && x + 8 <= w) return vload8(0, row + x);
  return (float8)(pv_at(row, x, w), pv_at(row, x + 1, w), pv_at(row, x + 2, w),
                  pv_at(row, x + 3, w), pv_at(row, x + 4, w), pv_at(row, x + 5, w),
                  pv_at(row, x + 6, w), pv_at(row, x + 7, w));
}

// The 8 pixels x .. x + 7 of row y; the gradients less (bu, bv) (I - mean) where valid (0: the
// plain gradients).
inline void pv_gradient8(__global const float* src, const int w, const int h, const int x, const int y,
                         const float8 bu, const float8 bv, const float mean, __global float* dst) {
  __global const float* row = src + y * w;
  const float8 c = pv_load8(row, x, w);
  const float8 l = pv_load8(row, x - 1, w);
  const float8 r = pv_load8(row, x + 1, w);
  const float8 t = y > 0 ? pv_load8(row - w, x, w) : (float8)(PV_INVALID);
  const float8 b = y + 1 < h ? pv_load8(row + w, x, w) : (float8)(PV_INVALID);
  const int8 valid = (c + l + r + t + b) >= 0.0f;
  const float8 zero = (float8)(0.0f);
  const float8 i = select(zero, c, valid);
  const float8 gu = select(zero, (r - l) * 0.5f - bu * (c - mean), valid);
  const float8 gv = select(zero, (b - t) * 0.5f - bv * (c - mean), valid);
  const float8 m = select(zero, (float8)(1.0f), valid);
  // One float4 per pixel: assembling them into two float16 first measured 1.5x slower on
  // PoCL (the shuffles cost more than the stores).
  __global float* o = dst + 4 * (y * w + x);
  const int n = w - x;
  vstore4((float4)(i.s0, gu.s0, gv.s0, m.s0), 0, o);
  if (n > 1) vstore4((float4)(i.s1, gu.s1, gv.s1, m.s1), 1, o);
  if (n > 2) vstore4((float4)(i.s2, gu.s2, gv.s2, m.s2), 2, o);
  if (n > 3) vstore4((float4)(i.s3, gu.s3, gv.s3, m.s3), 3, o);
  if (n > 4) vstore4((float4)(i.s4, gu.s4, gv.s4, m.s4), 4, o);
  if (n > 5) vstore4((float4)(i.s5, gu.s5, gv.s5, m.s5), 5, o);
  if (n > 6) vstore4((float4)(i.s6, gu.s6, gv.s6, m.s6), 6, o);
  if (n > 7) vstore4((float4)(i.s7, gu.s7, gv.s7, m.s7), 7, o);
}

__kernel __attribute__((reqd_work_group_size(PYRAMID_WG_X, PYRAMID_WG_Y, 1)))
void gradient(__global const float* src, const int w, const int h, __global float* dst) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= w || y >= h) return;
  pv_gradient8(src, w, h, x, y, (float8)(0.0f), (float8)(0.0f), 0.0f, dst);
}

// The gradients with the noise's share taken out (src/image/gradient_noise.h; plain C++
// reference: decorrelated_gradient_reference): beta, two floats (u, v) per pixel of the level.
__kernel __attribute__((reqd_work_group_size(PYRAMID_WG_X, PYRAMID_WG_Y, 1)))
void gradient_decorrelated(__global const float* src, const int w, const int h, __global float* dst,
                           __global const float* beta, const float mean) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= w || y >= h) return;
  __global const float* b = beta + 2 * (y * w + x);
  float16 p;
  if (x + 8 <= w) {
    p = vload16(0, b);
  } else {
    float tail[16];
    for (int k = 0; k < 16; ++k) tail[k] = k < 2 * (w - x) ? b[k] : 0.0f;
    p = vload16(0, tail);
  }
  pv_gradient8(src, w, h, x, y, p.even, p.odd, mean, dst);
}
