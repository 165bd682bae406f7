// The tracker's search for a first motion (src/track/motion_search.h): where the planar motion
// is unknown and the alignment from a guess fails (the first frames, a robot already at speed,
// a kick), many motion hypotheses are scored at once on one pyramid level by the zero-mean
// normalised cross-correlation of the reference and the live level warped through each
// hypothesis's homography. This pass only sums; the host forms the correlation in 64-bit precision.
//
// Per hypothesis h (a work-group) and per reference pixel p = (u, v) on a grid of every STEP-th
// column and row (an argument) with a valid reference sample R = ref(p):
//   q = H_h (u, v, 1); w(p) = (q.x / q.z, q.y / q.z)
//   L = bilinear sample of the live level's intensity at w(p), valid only when all four
//       neighbours are inside and valid (as kernels/track/warp_reduce.cl samples it)
//   a = I_r(p) - 128, b = L - 128 (centred, so that the sums of squares keep their precision in
//   float)
// and the pixel adds to the hypothesis's row of six sums: (n, sum a, sum b, sum a^2, sum b^2,
// sum a b) over its valid pairs.
//
// Work distribution: global (WG, hypotheses), work-group (WG, 1): work-item i of a group takes
// the grid's pixels i, i + WG, i + 2 WG, ... (row-major over the grid) and the group's sums
// meet in a local-memory tree. Row h of `sums` (6 floats) belongs to hypothesis h. The plain C++
// reference is motion_search_reference() in src/track/motion_search.cpp.
//
// Build options (-D): WG (64, a power of two).
#ifndef WG
#define WG 64
#endif

#define MS_NOUT 6

__kernel __attribute__((reqd_work_group_size(WG, 1, 1))) void motion_search(
    __global const float4* ref, const int ref_w, const int ref_h, __global const float4* live,
    const int live_w, const int live_h, __global const float* homographies, const int step,
    __global float* sums) {
  const int lid = (int)get_local_id(0);
  const int hyp = (int)get_group_id(1);
  __global const float* H = homographies + 9 * hyp;
  const float h0 = H[0], h1 = H[1], h2 = H[2];
  const float h3 = H[3], h4 = H[4], h5 = H[5];
  const float h6 = H[6], h7 = H[7], h8 = H[8];
  __global const float* refp = (__global const float*)ref;
  __global const float* livep = (__global const float*)live;
  const int cols = (ref_w + step - 1) / step, rows = (ref_h + step - 1) / step;
  const int count = cols * rows;

  float n = 0.0f, sa = 0.0f, sb = 0.0f, saa = 0.0f, sbb = 0.0f, sab = 0.0f;
  for (int i = lid; i < count; i += WG) {
    const int gy = i / cols;
    const int x = (i - gy * cols) * step, y = gy * step;
    const int ri = 4 * (y * ref_w + x);
    const float fu = (float)x, fv = (float)y;
    const float qx = h0 * fu + h1 * fv + h2;
    const float qy = h3 * fu + h4 * fv + h5;
    const float qz = h6 * fu + h7 * fv + h8;
    const float iz = qz > 1e-12f ? 1.0f / qz : 0.0f;
    const float wu = clamp(qx * iz, -1.0e6f, 1.0e6f), wv = clamp(qy * iz, -1.0e6f, 1.0e6f);
    const float bu = floor(wu), bv = floor(wv);
    const int iu = (int)bu, iv = (int)bv;
    const int inside = (qz > 1e-12f) & (iu >= 0) & (iv >= 0) & (iu < live_w - 1) & (iv < live_h - 1);
    const int b00 = inside ? 4 * (iv * live_w + iu) : 0;
    const int b10 = b00 + 4 * live_w;
    const float ax = wu - bu, ay = wv - bv;
    const float lI = (1.0f - ax) * (1.0f - ay) * livep[b00] + ax * (1.0f - ay) * livep[b00 + 4] +
                     (1.0f - ax) * ay * livep[b10] + ax * ay * livep[b10 + 4];
    const float m = inside ? refp[ri + 3] * livep[b00 + 3] * livep[b00 + 7] * livep[b10 + 3] * livep[b10 + 7]
                           : 0.0f;
    const float a = m * (refp[ri] - 128.0f), b = m * (lI - 128.0f);
    n += m;
    sa += a;
    sb += b;
    saa += a * a;
    sbb += b * b;
    sab += a * b;
  }

  __local float scratch[MS_NOUT * WG];
  scratch[0 * WG + lid] = n;
  scratch[1 * WG + lid] = sa;
  scratch[2 * WG + lid] = sb;
  scratch[3 * WG + lid] = saa;
  scratch[4 * WG + lid] = sbb;
  scratch[5 * WG + lid] = sab;
  for (int s = WG / 2; s > 0; s >>= 1) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lid < s) {
      for (int o = 0; o < MS_NOUT; ++o) scratch[o * WG + lid] += scratch[o * WG + lid + s];
    }
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid < MS_NOUT) sums[hyp * MS_NOUT + lid] = scratch[lid * WG];
}
