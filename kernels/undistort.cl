// Undistortion of the camera frame, the first stage of the image pipeline (src/image/pipeline.h;
// plain C++ reference: undistort_reference, which is remap_bilinear of src/image/undistort.h).
//
// Each work-item makes 8 consecutive pixels of a row: explicit float8 arithmetic, because PoCL
// does not vectorise this kernel across work-items (the bilinear arithmetic of one pixel is
// packed into short vectors first, which stops its work-item loop vectoriser); see
// src/image/README.md for the measurements.
//
//   src    the 8-bit frame, width x height, row stride == width
//   map    per output pixel the source (x, y) in frame pixels, interleaved; x < 0 where the
//          pixel has no source (0 <= x <= width - 1, 0 <= y <= height - 1 elsewhere); padded
//          with 8 pixels so that the last row's last work-item reads whole vectors
//   dst    width x height floats: the level-0 intensity image, UD_INVALID where no source

#ifndef UNDISTORT_WG_X
#define UNDISTORT_WG_X 16
#endif
#ifndef UNDISTORT_WG_Y
#define UNDISTORT_WG_Y 4
#endif

// pipeline.h's kInvalidIntensity.
#define UD_INVALID (-1048576.0f)

// Stores the first n (1..7) elements of v at d.
inline void ud_store_head(const float8 v, __global float* d, const int n) {
  d[0] = v.s0;
  if (n > 1) d[1] = v.s1;
  if (n > 2) d[2] = v.s2;
  if (n > 3) d[3] = v.s3;
  if (n > 4) d[4] = v.s4;
  if (n > 5) d[5] = v.s5;
  if (n > 6) d[6] = v.s6;
}

__kernel __attribute__((reqd_work_group_size(UNDISTORT_WG_X, UNDISTORT_WG_Y, 1)))
void undistort(__global const uchar* src, __global const float* map, const int width,
               const int height, __global float* dst) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= width || y >= height) return;
  const int p = y * width + x;
  // Lanes past the row's end read the next row's entries (or the padding): computed, not stored.
  const float16 m = vload16(0, map + 2 * p);
  const int8 valid = m.even >= 0.0f;
  // Pixels without a source sample pixel (0, 0), and are then overwritten.
  const float8 sx = select((float8)(0.0f), m.even, valid);
  const float8 sy = select((float8)(0.0f), m.odd, valid);
  const int8 x0 = convert_int8(sx), y0 = convert_int8(sy);  // truncation: sx, sy >= 0
  const float8 ax = sx - convert_float8(x0), ay = sy - convert_float8(y0);
  // On the last column/row the far neighbour has weight 0; clamp it to stay inside.
  const int8 i00 = y0 * width + x0;
  const int8 i10 = min(y0 + 1, height - 1) * width + x0;
  const int8 dx = select((int8)(1), (int8)(0), x0 >= width - 1);
  float8 p00, p01, p10, p11;
#define UD_GATHER(k)                    \
  p00.s##k = src[i00.s##k];             \
  p01.s##k = src[i00.s##k + dx.s##k];   \
  p10.s##k = src[i10.s##k];             \
  p11.s##k = src[i10.s##k + dx.s##k];
  UD_GATHER(0) UD_GATHER(1) UD_GATHER(2) UD_GATHER(3)
  UD_GATHER(4) UD_GATHER(5) UD_GATHER(6) UD_GATHER(7)
#undef UD_GATHER
  // remap_bilinear's operations, in its order.
  const float8 top = (1.0f - ax) * p00 + ax * p01;
  const float8 bottom = (1.0f - ax) * p10 + ax * p11;
  const float8 value = select((float8)(UD_INVALID), (1.0f - ay) * top + ay * bottom, valid);
  if (x + 8 <= width)
    vstore8(value, 0, dst + p);
  else
    ud_store_head(value, dst + p, width - x);
}
