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

// The photometric correction (src/image/photometric.h; plain C++ reference:
// photometric_reference): the light fixed to the camera taken out of the level-0 intensity
// image, between the undistortion and the prefilter. Per pixel, with raw the undistorted
// intensity:
//   dst = raw * scale + offset        where raw is valid, raw < saturation and scale > 0
//   dst = PV_INVALID                  otherwise (saturated, or the model says no value)
//
//   raw      width x height floats (PV_INVALID where no source)
//   model    2 planes of width x height floats: scale, then offset
//   dst      width x height floats
// Each work-item makes 8 consecutive pixels of a row (the launch shape of `undistort`).
__kernel __attribute__((reqd_work_group_size(UNDISTORT_WG_X, UNDISTORT_WG_Y, 1)))
void photometric(__global const float* raw, __global const float* model, const float saturation,
                 const int width, const int height, __global float* dst) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= width || y >= height) return;
  const int n = width * height;
  const int p = y * width + x;
  if (x + 8 <= width) {
    const float8 v = vload8(0, raw + p);
    const float8 scale = vload8(0, model + p), offset = vload8(0, model + n + p);
    const int8 use = (v > (float8)(0.5f * PV_INVALID)) & (v < (float8)(saturation)) & (scale > (float8)(0.0f));
    vstore8(select((float8)(PV_INVALID), v * scale + offset, use), 0, dst + p);
    return;
  }
  for (int i = p; i < y * width + width; ++i) {
    const float v = raw[i];
    const float scale = model[i];
    dst[i] = v > 0.5f * PV_INVALID && v < saturation && scale > 0.0f ? v * scale + model[n + i] : PV_INVALID;
  }
}

// The photometric model's statistics (plain C++ reference: photometric_learn_reference): from
// a frame in motion, every valid raw value (saturated ones included: a pixel that stays
// saturated has no contrast, which is how the model learns to leave it out) updates the
// pixel's exponential moving averages of the value and of its square,
//   mean += alpha (raw - mean);  square += alpha (raw^2 - square);
// with alpha = 1/n for the n-th frame these are the exact means.
//
//   raw      width x height floats (PV_INVALID where no source)
//   stats    2 planes of width x height floats: mean, then mean square (read and written)
__kernel __attribute__((reqd_work_group_size(UNDISTORT_WG_X, UNDISTORT_WG_Y, 1)))
void photometric_learn(__global const float* raw, __global float* stats, const float alpha,
                       const int width, const int height) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= width || y >= height) return;
  const int n = width * height;
  const int p = y * width + x;
  if (x + 8 <= width) {
    const float8 v = vload8(0, raw + p);
    const int8 valid = v > (float8)(0.5f * PV_INVALID);
    const float8 mean = vload8(0, stats + p), square = vload8(0, stats + n + p);
    vstore8(select(mean, mean + alpha * (v - mean), valid), 0, stats + p);
    vstore8(select(square, square + alpha * (v * v - square), valid), 0, stats + n + p);
    return;
  }
  for (int i = p; i < y * width + width; ++i) {
    const float v = raw[i];
    if (v > 0.5f * PV_INVALID) {
      stats[i] += alpha * (v - stats[i]);
      stats[n + i] += alpha * (v * v - stats[n + i]);
    }
  }
}

// Undistortion of a rolling-shutter camera's frame (src/image/rolling_shutter.h; plain C++
// reference: undistort_rolling_reference): the undistorted image a global shutter would have
// taken at the frame's stamp. Per output pixel p, with s(r) the map bilinearly interpolated at
// q = H_r p (rows' homographies interpolated linearly) and f(r) = s(r).y clamped to
// [0, height - 1]: r0 = the map's source row at p, r1 = f(r0), r2 = f(r1), and the frame is
// sampled bilinearly at s(aitken(r0, r1, r2)) when that lies inside the region of interest,
// PV_INVALID otherwise.
//
//   src      the 8-bit frame (as `undistort`'s)
//   map      per output pixel its source coordinate (x, y) under a global shutter
//   rows     height homographies of 9 floats, row-major
//   roi      (min x, min y, max x, max y) of the source coordinates that may be sampled
//   dst      width x height floats
// Each work-item makes 8 consecutive pixels of a row (the launch shape of `undistort`), one at
// a time: the gathers dominate.

inline float2 pv_map_at(__global const float2* map, const float2 q, const int width, const int height) {
  const float fx = isnan(q.x) ? 0.0f : floor(q.x), fy = isnan(q.y) ? 0.0f : floor(q.y);
  const int x0 = clamp((int)clamp(fx, -1.0f, (float)width), 0, width - 2);
  const int y0 = clamp((int)clamp(fy, -1.0f, (float)height), 0, height - 2);
  const float ax = q.x - (float)x0, ay = q.y - (float)y0;
  const int i00 = y0 * width + x0, i10 = i00 + width;
  // a + t (b - a): beyond the image's edge t is large, and this form keeps the rounding of the
  // map's coordinates from being multiplied by it.
  const float2 m00 = map[i00], m10 = map[i10];
  const float2 top = m00 + ax * (map[i00 + 1] - m00);
  const float2 bottom = m10 + ax * (map[i10 + 1] - m10);
  return top + ay * (bottom - top);
}

// s(r) for output pixel (u, v).
inline float2 pv_rolling_source(__global const float2* map, __global const float* rows, const float r,
                                const float u, const float v, const int width, const int height) {
  const int i = min((int)r, max(height - 2, 0));
  const float f = height > 1 ? r - (float)i : 0.0f;
  __global const float* a = rows + 9 * i;
  __global const float* b = height > 1 ? a + 9 : a;
  const float m0 = a[0] + f * (b[0] - a[0]), m1 = a[1] + f * (b[1] - a[1]), m2 = a[2] + f * (b[2] - a[2]);
  const float m3 = a[3] + f * (b[3] - a[3]), m4 = a[4] + f * (b[4] - a[4]), m5 = a[5] + f * (b[5] - a[5]);
  const float m6 = a[6] + f * (b[6] - a[6]), m7 = a[7] + f * (b[7] - a[7]), m8 = a[8] + f * (b[8] - a[8]);
  const float z = m6 * u + m7 * v + m8;
  return pv_map_at(map, (float2)((m0 * u + m1 * v + m2) / z, (m3 * u + m4 * v + m5) / z), width, height);
}

__kernel __attribute__((reqd_work_group_size(UNDISTORT_WG_X, UNDISTORT_WG_Y, 1)))
void undistort_rolling(__global const uchar* src, __global const float2* map, __global const float* rows,
                       const int width, const int height, const float4 roi, __global float* dst) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= width || y >= height) return;
  const int end = min(x + 8, width);
  const float last_row = (float)(height - 1), fv = (float)y;
  for (int u = x; u < end; ++u) {
    const int p = y * width + u;
    const float fu = (float)u;
    const float r0 = clamp(map[p].y, 0.0f, last_row);
    const float r1 = clamp(pv_rolling_source(map, rows, r0, fu, fv, width, height).y, 0.0f, last_row);
    const float r2 = clamp(pv_rolling_source(map, rows, r1, fu, fv, width, height).y, 0.0f, last_row);
    // Aitken's extrapolation (rolling_shutter.h, aitken()).
    const float d1 = r1 - r0, d2 = r2 - r1, den = d2 - d1;
    const float r = fabs(d2) < 0.9f * fabs(d1) && fabs(den) > 1e-4f ? clamp(r2 - d2 * d2 / den, 0.0f, last_row) : r2;
    const float2 s = pv_rolling_source(map, rows, r, fu, fv, width, height);
    if (!(s.x >= roi.x && s.x <= roi.z && s.y >= roi.y && s.y <= roi.w)) {
      dst[p] = PV_INVALID;
      continue;
    }
    const int x0 = (int)s.x, y0 = (int)s.y;
    const int x1 = min(x0 + 1, width - 1), y1 = min(y0 + 1, height - 1);
    const float ax = s.x - (float)x0, ay = s.y - (float)y0;
    const float top = (1.0f - ax) * (float)src[y0 * width + x0] + ax * (float)src[y0 * width + x1];
    const float bottom = (1.0f - ax) * (float)src[y1 * width + x0] + ax * (float)src[y1 * width + x1];
    dst[p] = (1.0f - ay) * top + ay * bottom;
  }
}
