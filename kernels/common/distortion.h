// OpenCV's radial-tangential distortion (k1 k2 p1 p2 k3) of undistorted normalised coordinates,
// exactly as cv::projectPoints applies it: the one copy of the polynomial. Kernels include it
// (cmake/EmbedKernels.cmake inlines it; float), and so does the host (core/camera.cpp in double,
// the mosaic's plain C++ reference in float, through kernels/mosaic/mosaic_project.h). Written in
// the subset that OpenCL C and C++ share; the operations in one order, so that the host's float
// reference and the kernel compute the same bits.
#ifndef PLANARVO_KERNELS_COMMON_DISTORTION_H
#define PLANARVO_KERNELS_COMMON_DISTORTION_H

// pv_radial_T(r2, k1, k2, k3) = 1 + k1 r² + k2 r⁴ + k3 r⁶ (Horner), and pv_distort_T: undistorted
// (x, y) to distorted (*xd, *yd).
#define PV_DEFINE_DISTORTION(T)                                                                    \
  inline T pv_radial_##T(const T r2, const T k1, const T k2, const T k3) {                         \
    return (T)1 + r2 * (k1 + r2 * (k2 + r2 * k3));                                                 \
  }                                                                                                \
  inline void pv_distort_##T(const T x, const T y, const T k1, const T k2, const T p1, const T p2, \
                             const T k3, T* xd, T* yd) {                                           \
    const T r2 = x * x + y * y;                                                                    \
    const T radial = pv_radial_##T(r2, k1, k2, k3);                                                \
    *xd = x * radial + (T)2 * p1 * x * y + p2 * (r2 + (T)2 * x * x);                               \
    *yd = y * radial + p1 * (r2 + (T)2 * y * y) + (T)2 * p2 * x * y;                               \
  }

PV_DEFINE_DISTORTION(float)
#ifndef __OPENCL_VERSION__
PV_DEFINE_DISTORTION(double)
#endif

#endif  // PLANARVO_KERNELS_COMMON_DISTORTION_H
