// Undistortion of the camera frame, the first stage of the image pipeline (src/image/pipeline.h;
// plain C++ reference: undistort_reference, which is remap_bilinear of src/image/undistort.h).
//
// Each work-item makes 8 consecutive pixels of a row with explicit float8 arithmetic: PoCL does
// not vectorise a per-pixel version across work-items (its SLP pass packs one pixel's bilinear
// arithmetic into short vectors first, which stops the work-item-loop vectoriser). The map is
// precomputed on the host (PipelineKernels::device_map): per pixel the index of the top-left
// source pixel and the float weights remap_bilinear computes, so the kernel does no floor,
// clamp or index arithmetic (40 % faster than sampling at float coordinates on PoCL).
//
//   src      the 8-bit frame, width x height, row stride == width, followed by at least
//            width + 1 readable bytes: the right/lower neighbour of a sample on the last
//            column/row is read, with weight 0
//   index    per output pixel y0 * width + x0 of its top-left source pixel, or -1 where the
//            pixel has no source; then 8 entries of -1 padding, so that the last work-item
//            reads whole vectors
//   weights  per output pixel (ax, ay) interleaved, the bilinear weights of the right and
//            lower neighbours; then 8 pixels of padding
//   dst      width x height floats: the level-0 intensity image, PV_INVALID where no source

#ifndef UNDISTORT_WG_X
#define UNDISTORT_WG_X 16
#endif
#ifndef UNDISTORT_WG_Y
#define UNDISTORT_WG_Y 4
#endif

// PV_INVALID and pv_store_head come from kernels/common.cl.

__kernel __attribute__((reqd_work_group_size(UNDISTORT_WG_X, UNDISTORT_WG_Y, 1)))
void undistort(__global const uchar* src, __global const int* index,
               __global const float* weights, const int width, const int height,
               __global float* dst) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= width || y >= height) return;
  const int p = y * width + x;
  // Lanes past the row's end read the next row's entries (or the padding): computed, not stored.
  const int8 i00 = vload8(0, index + p);
  const float16 w = vload16(0, weights + 2 * p);
  const float8 ax = w.even, ay = w.odd;
  const int8 valid = i00 >= 0;
  // Pixels without a source sample pixel (0, 0), and are then overwritten.
  const int8 i = max(i00, 0);
  float8 p00, p01, p10, p11;
#define UD_GATHER(k)                    \
  p00.s##k = src[i.s##k];               \
  p01.s##k = src[i.s##k + 1];           \
  p10.s##k = src[i.s##k + width];       \
  p11.s##k = src[i.s##k + width + 1];
  UD_GATHER(0) UD_GATHER(1) UD_GATHER(2) UD_GATHER(3)
  UD_GATHER(4) UD_GATHER(5) UD_GATHER(6) UD_GATHER(7)
#undef UD_GATHER
  // remap_bilinear's operations, in its order.
  const float8 top = (1.0f - ax) * p00 + ax * p01;
  const float8 bottom = (1.0f - ax) * p10 + ax * p11;
  const float8 value = select((float8)(PV_INVALID), (1.0f - ay) * top + ay * bottom, valid);
  if (x + 8 <= width)
    vstore8(value, 0, dst + p);
  else
    pv_store_head(value, dst + p, width - x);
}
