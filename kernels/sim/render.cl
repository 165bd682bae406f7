// The simulator's ground renderer (src/sim/simulator.h, src/sim/SIMULATOR.md).
//
// One work-item per output pixel. Each pixel averages S*S subsamples; a subsample's undistorted
// ray (from a table computed on the host in 64-bit precision) maps through its row's homography
// to texture coordinates (one per row: a rolling shutter sees each row from its own pose; a global
// shutter repeats one), and is looked up trilinearly in the mirror-tiled mip pyramid at the
// level of the pixel's footprint on the ground divided by S. render_reference() in
// src/sim/simulator_render.cpp is the plain C++ reference of this kernel: keep them in step.
//
// Buffers:
//   tex     all mip levels, row-major, one after another
//   levels  per level: offset into tex, width, height (powers of two)
//   pix     6 planes of width*height: pixel-centre ray x, y; d(ray)/d(pixel) j00 j01 j10 j11
//   sub     2*ns planes of width*height: subsample rays x, y
//   prm     H[9] (unused here: see hrows), 1/S, highest level, far value, 1/ns
//   out     width x height floats with the given row stride
//   hrows   height x 9 floats: row y's homography (ray -> texture coordinates), row-major

#ifndef RENDER_WG_X
#define RENDER_WG_X 16
#endif
#ifndef RENDER_WG_Y
#define RENDER_WG_Y 4
#endif

// The texel of texel index i of a texture of width w (a power of two) tiled by mirroring with
// period 2w: i & (2w - 1) is i mod 2w for negative i too (two's complement), then folded back.
inline int rnd_fold(int i, int w) {
  const int m = i & (2 * w - 1);
  return m < w ? m : 2 * w - 1 - m;
}

// Bilinear lookup at level coordinates (u, v), |u|, |v| < 2^30, of one level of the pyramid.
inline float rnd_bilinear(__global const float* tex, int offset, int w, int h, float u, float v) {
  const float x0 = floor(u), y0 = floor(v);
  const float fx = u - x0, fy = v - y0;
  const int xi = (int)x0, yi = (int)y0;
  const int xa = rnd_fold(xi, w), xb = rnd_fold(xi + 1, w);
  const int ya = rnd_fold(yi, h), yb = rnd_fold(yi + 1, h);
  __global const float* ra = tex + offset + ya * w;
  __global const float* rb = tex + offset + yb * w;
  const float top = ra[xa] + fx * (ra[xb] - ra[xa]);
  const float bottom = rb[xa] + fx * (rb[xb] - rb[xa]);
  return top + fy * (bottom - top);
}

__kernel __attribute__((reqd_work_group_size(RENDER_WG_X, RENDER_WG_Y, 1)))
void render_ground(__global const float* tex, __constant int* levels, __global const float* pix,
                   __global const float* sub, const int ns, __constant float* prm,
                   const int width, const int height, __global float* out, const int out_stride,
                   __global const float* hrows) {
  const int x = (int)get_global_id(0);
  const int y = (int)get_global_id(1);
  if (x >= width || y >= height) return;
  const int n = width * height;
  const int p = y * width + x;

  __global const float* hy = hrows + 9 * y;
  const float H0 = hy[0], H1 = hy[1], H2 = hy[2];
  const float H3 = hy[3], H4 = hy[4], H5 = hy[5];
  const float H6 = hy[6], H7 = hy[7], H8 = hy[8];
  const float inv_s = prm[9], lod_max = prm[10], far_value = prm[11], inv_count = prm[12];

  // Level of detail from the pixel centre: the longer side of the subsample's footprint,
  // d(u, v)/d(pixel) / S, in level-0 texels.
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
    const float len2 = fmax(b00 * b00 + b10 * b10, b01 * b01 + b11 * b11);
    // A footprint of at most one texel is level 0 whatever log2 says (it is <= 0 there): the
    // common case, and log2 is a good part of the kernel's time on a CPU.
    if (g2 < 0.0f && len2 < 1e30f)
      lod = len2 <= 1.0f ? 0.0f : clamp(0.5f * log2(fmax(len2, 1e-30f)), 0.0f, lod_max);
  }
  const int l0 = (int)lod;
  const int l1 = min(l0 + 1, (int)lod_max);
  const float f = lod - (float)l0;
  const float s0 = 1.0f / (float)(1 << l0), s1 = 1.0f / (float)(1 << l1);
  const int o0 = levels[3 * l0], w0 = levels[3 * l0 + 1], h0 = levels[3 * l0 + 2];
  const int o1 = levels[3 * l1], w1 = levels[3 * l1 + 1], h1 = levels[3 * l1 + 2];

  float acc = 0.0f;
  for (int s = 0; s < ns; ++s) {
    const float rx = sub[(2 * s) * n + p], ry = sub[(2 * s + 1) * n + p];
    const float g0 = H0 * rx + H1 * ry + H2;
    const float g1 = H3 * rx + H4 * ry + H5;
    const float g2 = H6 * rx + H7 * ry + H8;
    const float iw = 1.0f / g2;
    const float u = g0 * iw, v = g1 * iw;
    // Rays that miss the ground, or meet it absurdly far away, see the texture's mean.
    if (!(g2 < 0.0f && fabs(u) < 1e7f && fabs(v) < 1e7f)) {
      acc += far_value;
      continue;
    }
    const float t0 = rnd_bilinear(tex, o0, w0, h0, (u + 0.5f) * s0 - 0.5f, (v + 0.5f) * s0 - 0.5f);
    if (f > 0.0f) {
      const float t1 = rnd_bilinear(tex, o1, w1, h1, (u + 0.5f) * s1 - 0.5f, (v + 0.5f) * s1 - 0.5f);
      acc += t0 + f * (t1 - t0);
    } else {
      acc += t0;
    }
  }
  out[y * out_stride + x] = acc * inv_count;
}
