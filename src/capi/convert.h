// Conversions between the C API's plain structs and the engine's C++ types, and the reading and
// writing of versioned structs (struct_size first) as far as the caller's struct_size reaches.
#pragma once
#include <algorithm>
#include <cstring>
#include <string>
#include <type_traits>

#include <Eigen/Core>

#include "core/extrinsics.h"
#include "core/motion.h"
#include "core/se2.h"
#include "core/camera.h"
#include "planarvo/planarvo.h"

namespace planarvo::capi {

// The integer a caller stored in a C enum field. A value outside the enum's constants may not be
// read as the enum itself in C++ (undefined behaviour, which UBSan reports), so its bytes are
// read as the underlying integer: check the result against the constants, then convert.
template <class E>
int enum_value(const E& e) {
  std::underlying_type_t<E> v;
  std::memcpy(&v, &e, sizeof v);
  return static_cast<int>(v);
}

// Copies src into a fixed-size C string field, truncating and always terminating.
inline void copy_string(char* dst, size_t capacity, const std::string& src) {
  const size_t n = std::min(capacity - 1, src.size());
  std::memcpy(dst, src.data(), n);
  dst[n] = '\0';
}

inline CameraModel to_cpp(const planarvo_camera& c) {
  CameraModel m;
  m.width = c.width; m.height = c.height;
  m.fx = c.fx; m.fy = c.fy; m.cx = c.cx; m.cy = c.cy;
  m.k1 = c.k1; m.k2 = c.k2; m.p1 = c.p1; m.p2 = c.p2; m.k3 = c.k3;
  m.roi = PixelRegion{c.roi.x, c.roi.y, c.roi.width, c.roi.height};
  m.rolling_shutter_readout = c.rolling_shutter_readout;
  m.exposure_time = c.exposure_time;
  return m;
}
inline planarvo_camera to_c(const CameraModel& m) {
  return {m.width, m.height, m.fx, m.fy, m.cx, m.cy, m.k1, m.k2, m.p1, m.p2, m.k3,
          {m.roi.x, m.roi.y, m.roi.width, m.roi.height}, m.rolling_shutter_readout, m.exposure_time};
}
inline Extrinsics to_cpp(const planarvo_extrinsics& e) { return {e.x, e.y, e.z, e.roll, e.pitch, e.yaw}; }
inline planarvo_extrinsics to_c(const Extrinsics& e) { return {e.x, e.y, e.z, e.roll, e.pitch, e.yaw}; }
inline SE2 to_cpp(const planarvo_se2& p) { return {p.x, p.y, p.theta}; }
inline planarvo_se2 to_c(const SE2& p) { return {p.x, p.y, p.theta}; }

// Square matrices (covariances) cross the C API as N·N doubles, row-major.
template <int N>
Eigen::Matrix<double, N, N> matrix_from_c(const double* m) {
  return Eigen::Map<const Eigen::Matrix<double, N, N, Eigen::RowMajor>>(m);
}
template <int N>
void matrix_to_c(const Eigen::Matrix<double, N, N>& m, double* out) {
  Eigen::Map<Eigen::Matrix<double, N, N, Eigen::RowMajor>> to(out);
  to = m;
}

// A motion with its optional covariance as the C structs carry it: the motion, a has_ flag and
// 9 doubles. Not given is a zero covariance on the C++ side (core/motion.h).
inline Motion motion_from_c(const planarvo_se2& value, int32_t has_covariance, const double* covariance) {
  Motion m{to_cpp(value)};
  if (has_covariance) m.covariance = matrix_from_c<3>(covariance);
  return m;
}
inline void motion_to_c(const Motion& m, planarvo_se2* value, int32_t* has_covariance, double* covariance) {
  *value = to_c(m.value);
  *has_covariance = m.has_covariance() ? 1 : 0;
  matrix_to_c<3>(m.covariance, covariance);
}

// A caller's versioned struct over the defaults, as far as its struct_size reaches: fields that a
// shorter (older) struct lacks keep their defaults. struct_size must already be checked against
// the first version's size (require_struct_size).
template <class T>
T read_versioned(const T& in, T defaults) {
  std::memcpy(static_cast<void*>(&defaults), &in, std::min(in.struct_size, sizeof(T)));
  defaults.struct_size = sizeof(T);
  return defaults;
}
// Writes value into the caller's struct, no further than its struct_size, which it keeps.
template <class T>
void write_versioned(T value, T* out) {
  value.struct_size = out->struct_size;
  std::memcpy(static_cast<void*>(out), &value, std::min(out->struct_size, sizeof(T)));
}

}  // namespace planarvo::capi
