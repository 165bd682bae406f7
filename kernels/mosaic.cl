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
// prm (see MosaicWarpParam in mosaic_warp.h):
//   0..8   H, row-major: (col + 0.5, row + 0.5, 1) of the window -> (X, Y, Z) camera frame
//   9..12  fx fy cx cy        13..17 k1 k2 p1 p2 k3
//   18     largest squared radius of an undistorted ray inside the image (the model's domain)
//   19..22 region of interest: first column, first row, last column, last row (inclusive)
//   23     1 / feathering ramp in pixels of the frame
//   24..25 the camera's foot point in window pixel coordinates   26 squared range limit (px^2)

#ifndef MOSAIC_WG_X
#define MOSAIC_WG_X 16
#endif
#ifndef MOSAIC_WG_Y
#define MOSAIC_WG_Y 4
#endif

__kernel __attribute__((reqd_work_group_size(MOSAIC_WG_X, MOSAIC_WG_Y, 1)))
void mosaic_warp(__global const uchar* frame, const int frame_stride, __constant float* prm,
                 const int width, const int height, __global float* out) {
  const int col = (int)get_global_id(0);
  const int row = (int)get_global_id(1);
  if (col >= width || row >= height) return;
  const int o = 2 * (row * width + col);

  const float mx = (float)col + 0.5f, my = (float)row + 0.5f;
  const float dx = mx - prm[24], dy = my - prm[25];
  const float X = prm[0] * mx + prm[1] * my + prm[2];
  const float Y = prm[3] * mx + prm[4] * my + prm[5];
  const float Z = prm[6] * mx + prm[7] * my + prm[8];
  float value = 0.0f, weight = 0.0f;
  if (Z > 0.0f && dx * dx + dy * dy <= prm[26]) {
    const float iz = 1.0f / Z;
    const float x = X * iz, y = Y * iz;
    const float r2 = x * x + y * y;
    if (r2 <= prm[18]) {
      const float k1 = prm[13], k2 = prm[14], p1 = prm[15], p2 = prm[16], k3 = prm[17];
      const float radial = 1.0f + r2 * (k1 + r2 * (k2 + r2 * k3));
      const float xd = x * radial + 2.0f * p1 * x * y + p2 * (r2 + 2.0f * x * x);
      const float yd = y * radial + p1 * (r2 + 2.0f * y * y) + 2.0f * p2 * x * y;
      const float u = prm[9] * xd + prm[11];
      const float v = prm[10] * yd + prm[12];
      // All four bilinear neighbours inside the region of interest.
      if (u >= prm[19] && v >= prm[20] && u < prm[21] && v < prm[22]) {
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
    }
  }
  out[o] = value;
  out[o + 1] = weight;
}
