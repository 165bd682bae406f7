// The mosaic warp's parameter layout and its projection of a window pixel into the frame: one copy
// that the kernel (kernels/mosaic/mosaic.cl) and its plain C++ reference
// (src/mosaic/mosaic_warp.cpp) include, in the subset that OpenCL C and C++ share.
#ifndef PLANARVO_KERNELS_MOSAIC_MOSAIC_PROJECT_H
#define PLANARVO_KERNELS_MOSAIC_MOSAIC_PROJECT_H

#include "kernels/common/distortion.h"

// Where each parameter starts in the warp's parameter block (floats):
#define PV_MOSAIC_H 0             // 9: window pixel (col + 0.5, row + 0.5, 1) -> camera-frame ground point
#define PV_MOSAIC_INTRINSICS 9    // fx fy cx cy
#define PV_MOSAIC_DISTORTION 13   // k1 k2 p1 p2 k3
#define PV_MOSAIC_MAX_RADIUS2 18  // the distortion model's domain: squared undistorted radius
#define PV_MOSAIC_REGION 19       // first column, first row, last column, last row (inclusive)
#define PV_MOSAIC_INV_FEATHER 23  // 1 / the feathering ramp in frame pixels
#define PV_MOSAIC_FOOT 24         // 2: the camera's foot point in window pixels
#define PV_MOSAIC_RANGE2 26       // squared range limit in mosaic pixels
#define PV_MOSAIC_H_MIDDLE 27     // 9: H when the frame's middle row was read (a rolling shutter)
#define PV_MOSAIC_H_LAST 36       // 9: H when its last row was read
#define PV_MOSAIC_INV_ROWS 45     // 1 / (rows - 1) for a rolling shutter, 0 for a global shutter
#define PV_MOSAIC_PARAM_COUNT 46

#ifdef __OPENCL_VERSION__
#define PV_MOSAIC_PARAMS __constant float*
#else
#define PV_MOSAIC_PARAMS const float*
#endif

// Window pixel (mx, my) to the distorted frame pixel (*u, *v) through H(s), the quadratic through
// the three rows' homographies (s: the read time's fraction of the frame; H(0) = H for a global
// shutter); 0 where the ground point is behind the camera or outside the distortion model's domain.
inline int pv_mosaic_project(PV_MOSAIC_PARAMS prm, const float mx, const float my, const float s, float* u,
                             float* v) {
  const float w0 = (1.0f - s) * (1.0f - 2.0f * s), wm = 4.0f * s * (1.0f - s), w1 = s * (2.0f * s - 1.0f);
  // Each H(s) entry as w0 H + wm H_middle + w1 H_last, inline in one expression (the kernel's
  // compiler may fuse within an expression; keeping this form keeps its results).
#define PV_MOSAIC_HS(i) \
  (w0 * prm[PV_MOSAIC_H + (i)] + wm * prm[PV_MOSAIC_H_MIDDLE + (i)] + w1 * prm[PV_MOSAIC_H_LAST + (i)])
  const float X = PV_MOSAIC_HS(0) * mx + PV_MOSAIC_HS(1) * my + PV_MOSAIC_HS(2);
  const float Y = PV_MOSAIC_HS(3) * mx + PV_MOSAIC_HS(4) * my + PV_MOSAIC_HS(5);
  const float Z = PV_MOSAIC_HS(6) * mx + PV_MOSAIC_HS(7) * my + PV_MOSAIC_HS(8);
#undef PV_MOSAIC_HS
  if (!(Z > 0.0f)) return 0;
  const float iz = 1.0f / Z;
  const float x = X * iz, y = Y * iz;
  if (!(x * x + y * y <= prm[PV_MOSAIC_MAX_RADIUS2])) return 0;
  const int d = PV_MOSAIC_DISTORTION;
  float xd = 0.0f, yd = 0.0f;
  pv_distort_float(x, y, prm[d], prm[d + 1], prm[d + 2], prm[d + 3], prm[d + 4], &xd, &yd);
  *u = prm[PV_MOSAIC_INTRINSICS] * xd + prm[PV_MOSAIC_INTRINSICS + 2];
  *v = prm[PV_MOSAIC_INTRINSICS + 1] * yd + prm[PV_MOSAIC_INTRINSICS + 3];
  return 1;
}

#endif  // PLANARVO_KERNELS_MOSAIC_MOSAIC_PROJECT_H
