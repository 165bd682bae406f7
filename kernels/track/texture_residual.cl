// The honest-status check's sums (src/track/texture_residual.h): over the pixels of a residual
// image whose 3 x 3 neighbourhood is valid (every Huber weight > 0), |N*r| and |N*I_r| with
// Immerkaer's operator N = [1 -2 1; -2 4 -2; 1 -2 1], and their count, one row of three partial
// sums per work-group (local-memory tree reduction; the host sums the rows in 64-bit floating point). Plain C++
// reference: texture_residual() in src/track/texture_residual.cpp, on the residual image read back.
//
//   debug    w x h float4 (r, weight, valid, rho): the DEBUG_OUTPUT pass of warp_reduce.cl
//   ref      w x h float4 (I, dI/du, dI/dv, valid): the keyframe's level (pyramid.h)
//   partials 3 floats per work-group: sum |N*r|, sum |N*I_r|, count
// One work-item per pixel, 2-D range rounded up to TR_WG_X x TR_WG_Y; pixels outside are not
// counted. Work-group (group_id(0) + num_groups(0) * group_id(1)) writes row g.
#ifndef TR_WG_X
#define TR_WG_X 16
#endif
#ifndef TR_WG_Y
#define TR_WG_Y 4
#endif
#define TR_WG (TR_WG_X * TR_WG_Y)

__kernel __attribute__((reqd_work_group_size(TR_WG_X, TR_WG_Y, 1)))
void texture_residual(__global const float4* debug, __global const float4* ref, const int w, const int h,
                      __global float* partials) {
  const int x = (int)get_global_id(0), y = (int)get_global_id(1);
  float sr = 0.0f, si = 0.0f, n = 0.0f;
  if (x >= 1 && y >= 1 && x + 1 < w && y + 1 < h) {
    float nr = 0.0f, ni = 0.0f;
    int valid = 1;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int q = (y + dy) * w + (x + dx);
        const float c = (dx == 0 && dy == 0) ? 4.0f : ((dx == 0 || dy == 0) ? -2.0f : 1.0f);
        const float4 d = debug[q];
        valid &= d.y > 0.0f;
        nr += c * d.x;
        ni += c * ref[q].x;
      }
    if (valid) {
      sr = fabs(nr);
      si = fabs(ni);
      n = 1.0f;
    }
  }
  __local float scratch[3 * TR_WG];
  const int lid = (int)get_local_id(1) * TR_WG_X + (int)get_local_id(0);
  scratch[lid] = sr;
  scratch[TR_WG + lid] = si;
  scratch[2 * TR_WG + lid] = n;
  for (int s = TR_WG / 2; s > 0; s >>= 1) {
    barrier(CLK_LOCAL_MEM_FENCE);
    if (lid < s) {
      scratch[lid] += scratch[lid + s];
      scratch[TR_WG + lid] += scratch[TR_WG + lid + s];
      scratch[2 * TR_WG + lid] += scratch[2 * TR_WG + lid + s];
    }
  }
  if (lid == 0) {
    const int g = (int)get_group_id(0) + (int)get_num_groups(0) * (int)get_group_id(1);
    partials[3 * g] = scratch[0];
    partials[3 * g + 1] = scratch[TR_WG];
    partials[3 * g + 2] = scratch[2 * TR_WG];
  }
}
