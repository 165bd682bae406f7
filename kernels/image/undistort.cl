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

// PV_INVALID, pv_store_head and pv_load_head come from kernels/common/common.cl.

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

// A row warp's field (RowWarp::delta or RowWarp::light, nodes_x x nodes_y float2, row-major) at
// the eight pixels (x .. x + 7, y), interpolated bilinearly as row_warp_at (rolling_shutter.h):
// (dx of the eight, dy of the eight). Eight pixels span at most two cells of a grid with a step
// of 8 or more, so the grid is read at three node columns from the first lane's, interpolated
// between the two rows first; lanes past the row's end are computed, not stored.
inline float16 pv_row_warp8(__global const float2* field, const int nodes_x, const int nodes_y,
                            const float inv_step, const int x, const int y) {
  const float gy = (float)y * inv_step;
  const int j = min((int)gy, nodes_y - 2);
  const float ay = gy - (float)j;
  const float8 gx = convert_float8((int8)(x) + (int8)(0, 1, 2, 3, 4, 5, 6, 7)) * inv_step;
  const int8 cell = min(convert_int8(gx), (int8)(nodes_x - 2));
  const float8 ax = gx - convert_float8(cell);
  const int i0 = cell.s0, i2 = min(i0 + 2, nodes_x - 1);
  const int g0 = j * nodes_x, g1 = g0 + nodes_x;
  const float2 c0 = field[g0 + i0] + ay * (field[g1 + i0] - field[g0 + i0]);
  const float2 c1 = field[g0 + i0 + 1] + ay * (field[g1 + i0 + 1] - field[g0 + i0 + 1]);
  const float2 c2 = field[g0 + i2] + ay * (field[g1 + i2] - field[g0 + i2]);
  const int8 second = cell > (int8)(i0);  // the lane lies in the next cell
  const float8 lx = select((float8)(c0.x), (float8)(c1.x), second), rx = select((float8)(c1.x), (float8)(c2.x), second);
  const float8 ly = select((float8)(c0.y), (float8)(c1.y), second), ry = select((float8)(c1.y), (float8)(c2.y), second);
  float16 d;
  d.lo = lx + ax * (rx - lx);
  d.hi = ly + ax * (ry - ly);
  return d;
}

// The photometric correction of a rolling-shutter frame (plain C++ reference:
// photometric_rolling_reference): as `photometric`, but the model is read where the light of
// each pixel is. `undistort_rolling` reads output pixel p from camera pixel distort(H_r p), which
// the model (per undistorted pixel of a global shutter) has at q = p + light(p); light is the
// row warp's second field (RowWarp::light), interpolated as `undistort_rolling` interpolates its
// first (between the node rows first). The model is read at the pixel nearest q clamped to the
// image (two gathers a pixel, where bilinear sampling takes eight); a pixel has no value where
// that one's scale is 0.
//
//   raw      width x height floats (PV_INVALID where no source): undistort_rolling's output
//   model    2 planes of width x height floats: scale, then offset
//   grid     2 fields of nodes_x x nodes_y float2: RowWarp::delta, then RowWarp::light
//   dst      width x height floats
// Each work-item makes 8 consecutive pixels of a row (the launch shape of `undistort`).
__kernel __attribute__((reqd_work_group_size(UNDISTORT_WG_X, UNDISTORT_WG_Y, 1)))
void photometric_rolling(__global const float* raw, __global const float* model, __global const float2* grid,
                         const int nodes_x, const int nodes_y, const float inv_step, const float saturation,
                         const int width, const int height, __global float* dst) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= width || y >= height) return;
  const int n = width * height;
  // The light field at the eight pixels.
  const float16 d = pv_row_warp8(grid + nodes_x * nodes_y, nodes_x, nodes_y, inv_step, x, y);
  const float8 u = convert_float8((int8)(x) + (int8)(0, 1, 2, 3, 4, 5, 6, 7));
  const float8 qx = clamp(u + d.lo, 0.0f, (float)(width - 1));
  const float8 qy = clamp((float8)((float)y) + d.hi, 0.0f, (float)(height - 1));
  // The nearest model pixel: the model is smooth over tens of pixels (a box of the image's width
  // / 40), so half a pixel changes it by under 0.1 %; where it is not (a shadow's edge) it has
  // no value.
  const int8 t = convert_int8(qy + 0.5f) * width + convert_int8(qx + 0.5f);
  float8 scale, offset;
#define PR_GATHER(k) scale.s##k = model[t.s##k]; offset.s##k = model[n + t.s##k];
  PR_GATHER(0) PR_GATHER(1) PR_GATHER(2) PR_GATHER(3) PR_GATHER(4) PR_GATHER(5) PR_GATHER(6) PR_GATHER(7)
#undef PR_GATHER
  const int p = y * width + x;
  const float8 v = x + 8 <= width ? vload8(0, raw + p) : pv_load_head(raw + p, width - x, PV_INVALID);
  const int8 use = (v > (float8)(0.5f * PV_INVALID)) & (v < (float8)(saturation)) & (scale > (float8)(0.0f));
  const float8 value = select((float8)(PV_INVALID), v * scale + offset, use);
  if (x + 8 <= width)
    vstore8(value, 0, dst + p);
  else
    pv_store_head(value, dst + p, width - x);
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
// taken at the frame's stamp. Per output pixel p = (u, v): the source coordinate is the map's
// plus the rolling shutter's displacement, interpolated bilinearly from a grid of nodes every
// `step` pixels, 8 or more (cells clamped to the grid; between the node rows first); the frame is sampled there bilinearly when it lies
// inside the region of interest, PV_INVALID otherwise.
//
//   src      the 8-bit frame (as `undistort`'s)
//   map      per output pixel its source coordinate (x, y) under a global shutter, then 8
//            pairs of padding
//   grid     nodes_x x nodes_y displacements (dx, dy), row-major
//   inv_step 1 / the grid's step
//   roi      (min x, min y, max x, max y) of the source coordinates that may be sampled
//   dst      width x height floats
// Each work-item makes 8 consecutive pixels of a row with float8 arithmetic (as `undistort`).
__kernel __attribute__((reqd_work_group_size(UNDISTORT_WG_X, UNDISTORT_WG_Y, 1)))
void undistort_rolling(__global const uchar* src, __global const float* map, __global const float2* grid,
                       const int nodes_x, const int nodes_y, const float inv_step, const int width,
                       const int height, const float4 roi, __global float* dst) {
  const int x = (int)get_global_id(0) * 8;
  const int y = (int)get_global_id(1);
  if (x >= width || y >= height) return;
  // The rolling shutter's displacement at the eight pixels.
  const float16 d = pv_row_warp8(grid, nodes_x, nodes_y, inv_step, x, y);
  // The map's eight (x, y) pairs (the last work-item of a row may read into the next row: the
  // map is padded by 8 pairs).
  const float16 m = vload16(0, map + 2 * (y * width + x));
  const float8 sx = m.even + d.lo;
  const float8 sy = m.odd + d.hi;
  const int8 valid = (sx >= (float8)(roi.x)) & (sx <= (float8)(roi.z)) & (sy >= (float8)(roi.y)) & (sy <= (float8)(roi.w));
  // The top-left tap clamped to the second-last column and row, where the weight of the right or
  // lower tap is then 1 (exactly the last pixel's value, as the reference's clamped taps give),
  // so that the four taps are base, base + 1, base + width and base + width + 1 as `undistort`'s
  // (the frame is padded for the last row's). Invalid lanes sample pixel (0, 0), then overwritten.
  const int8 x0 = min(convert_int8(select((float8)(0.0f), sx, valid)), (int8)(max(width - 2, 0)));
  const int8 y0 = min(convert_int8(select((float8)(0.0f), sy, valid)), (int8)(max(height - 2, 0)));
  const float8 fx = select((float8)(0.0f), sx - convert_float8(x0), valid);
  const float8 fy = select((float8)(0.0f), sy - convert_float8(y0), valid);
  const int8 i = y0 * width + x0;
  float8 p00, p01, p10, p11;
#define UR_GATHER(k)                 \
  p00.s##k = src[i.s##k];            \
  p01.s##k = src[i.s##k + 1];        \
  p10.s##k = src[i.s##k + width];    \
  p11.s##k = src[i.s##k + width + 1];
  UR_GATHER(0) UR_GATHER(1) UR_GATHER(2) UR_GATHER(3) UR_GATHER(4) UR_GATHER(5) UR_GATHER(6) UR_GATHER(7)
#undef UR_GATHER
  const float8 top = (1.0f - fx) * p00 + fx * p01;
  const float8 bottom = (1.0f - fx) * p10 + fx * p11;
  const float8 value = select((float8)(PV_INVALID), (1.0f - fy) * top + fy * bottom, valid);
  if (x + 8 <= width)
    vstore8(value, 0, dst + y * width + x);
  else
    pv_store_head(value, dst + y * width + x, width - x);
}
