// Conversions between the C API's plain structs and the engine's C++ types.
#pragma once
#include <algorithm>
#include <cstring>
#include <string>

#include "core/extrinsics.h"
#include "core/se2.h"
#include "image/camera.h"
#include "planarvo/planarvo.h"

namespace planarvo::capi {

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
  return m;
}
inline planarvo_camera to_c(const CameraModel& m) {
  return {m.width, m.height, m.fx, m.fy, m.cx, m.cy, m.k1, m.k2, m.p1, m.p2, m.k3};
}
inline Extrinsics to_cpp(const planarvo_extrinsics& e) { return {e.x, e.y, e.z, e.roll, e.pitch, e.yaw}; }
inline planarvo_extrinsics to_c(const Extrinsics& e) { return {e.x, e.y, e.z, e.roll, e.pitch, e.yaw}; }
inline SE2 to_cpp(const planarvo_se2& p) { return {p.x, p.y, p.theta}; }
inline planarvo_se2 to_c(const SE2& p) { return {p.x, p.y, p.theta}; }

}  // namespace planarvo::capi
