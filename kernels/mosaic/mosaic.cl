// The floor mosaic's warp (src/mosaic/mosaic_warp.h, src/mosaic/README.md).
//
// One work-item per mosaic pixel of a window (the part of the mosaic one frame can see). The
// pixel centre maps through the frame's homography H (window pixel -> camera-frame point on the
// ground plane, up to scale: the paper's plane-induced homography, eq. 3, from the mosaic's ground
// grid instead of a reference image) to the undistorted normalised ray, then through OpenCV's
// radial-tangential model to a distorted pixel of the 8-bit frame, which is sampled bilinearly.
// Writes (value, weight) per window pixel: weight 0 where the pixel is not seen (behind the
// camera, outside the calibrated field of view, outside the region of interest, farther than the
// range limit); else the feathering weight, rising linearly from the region's border.
// mosaic_warp_reference() in src/mosaic/mosaic_warp.cpp is the plain C++ reference: keep them in
// step.
//
// prm (kernels/mosaic/mosaic_project.h names the offsets; mosaic_warp.h's MosaicWarpParam uses them):
//   0..8   H, row-major: (col + 0.5, row + 0.5, 1) of the window -> (X, Y, Z) camera frame
//   9..12  fx fy cx cy        13..17 k1 k2 p1 p2 k3
//   18     largest squared radius of an undistorted ray inside the image (the model's domain)
//   19..22 region of interest: first column, first row, last column, last row (inclusive)
//   23     1 / feathering ramp in pixels of the frame
//   24..25 the camera's foot point in window pixel coordinates   26 squared range limit (px^2)
//   27..35 H when the frame's middle row was read, 36..44 when its last row was (a rolling
//          shutter; row r is read at stamp + r / (rows - 1) * readout, docs/conventions.md)
//   45     1 / (rows - 1) of the frame for a rolling shutter, 0 for a global shutter
//
// With a rolling shutter each ground point is sampled on the row that saw it, the fixed point
// r = v(H(s)), s = r / (rows - 1), H(s) the quadratic through the three rows' homographies: two
// fixed-point steps from the first row's projection, then two secant steps (the first is
// Aitken's extrapolation, exact for a row that is an affine function of s): four projections.

#ifndef MOSAIC_WG_X
#define MOSAIC_WG_X 16
#endif
#ifndef MOSAIC_WG_Y
#define MOSAIC_WG_Y 4
#endif

#include "kernels/mosaic/mosaic_project.h"

__kernel __attribute__((reqd_work_group_size(MOSAIC_WG_X, MOSAIC_WG_Y, 1)))
void mosaic_warp(__global const uchar* frame, const int frame_stride, __constant float* prm,
                 const int width, const int height, __global float* out) {
  const int col = (int)get_global_id(0);
  const int row = (int)get_global_id(1);
  if (col >= width || row >= height) return;
  const int o = 2 * (row * width + col);

  const float mx = (float)col + 0.5f, my = (float)row + 0.5f;
  const float dx = mx - prm[24], dy = my - prm[25];
  float value = 0.0f, weight = 0.0f, u = 0.0f, v = 0.0f;
  int seen = dx * dx + dy * dy <= prm[26] && pv_mosaic_project(prm, mx, my, 0.0f, &u, &v);
  const float inv_rows = prm[45];
  if (seen && inv_rows > 0.0f) {
    // The steps are not clamped to the frame's rows (a clamped step breaks the extrapolation for
    // a point seen near the first or last row): H(s) is extrapolated up to half a readout beyond
    // them. Only the answer is clamped to them: a point no row saw (its fixed point beyond the
    // last row) still projects beyond that row from it, since the map's slope is below 1.
    const float s1 = clamp(v * inv_rows, -0.5f, 1.5f);
    seen = pv_mosaic_project(prm, mx, my, s1, &u, &v);
    const float s2 = clamp(v * inv_rows, -0.5f, 1.5f);
    // f(s) = g(s) - s, g(s) = v(s) / (rows - 1): the root by secant steps, the first through
    // (0, s1) and (s1, s2 - s1), which is Aitken's extrapolation of 0, s1, s2.
    const float f1 = s2 - s1;
    const float den1 = f1 - s1;
    const float sa = fabs(den1) > 1e-7f ? clamp(s1 - f1 * s1 / den1, -0.5f, 1.5f) : s2;
    seen = seen && pv_mosaic_project(prm, mx, my, sa, &u, &v);
    const float fa = v * inv_rows - sa;
    const float den2 = fa - f1;
    const float sb = fabs(den2) > 1e-7f ? sa - fa * (sa - s1) / den2 : sa + fa;
    seen = seen && pv_mosaic_project(prm, mx, my, clamp(sb, 0.0f, 1.0f), &u, &v);
  }
  // All four bilinear neighbours inside the region of interest.
  if (seen && u >= prm[19] && v >= prm[20] && u < prm[21] && v < prm[22]) {
    const float u0 = floor(u), v0 = floor(v);
    const float fu = u - u0, fv = v - v0;
    __global const uchar* p = frame + (int)v0 * frame_stride + (int)u0;
    const float a = (float)p[0], b = (float)p[1];
    const float c = (float)p[frame_stride], d = (float)p[frame_stride + 1];
    const float top = a + fu * (b - a);
    const float bottom = c + fu * (d - c);
    value = top + fv * (bottom - top);
    const float edge = fmin(fmin(u - prm[19], prm[21] - u), fmin(v - prm[20], prm[22] - v));
    weight = fmin(1.0f, (edge + 0.5f) * prm[23]);
  }
  out[o] = value;
  out[o + 1] = weight;
}
