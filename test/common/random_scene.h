// Random cameras and camera poses on the robot for the kernel tests (the renderer's, the mosaic's):
// plausible lenses (50-90 degree fields of view, barrel distortion) and tilts.
#pragma once
#include <cmath>

#include "core/extrinsics.h"
#include "core/camera.h"
#include "sim/simulator.h"

namespace planarvo::test {

inline CameraModel random_camera(sim::Random& r, int w, int h) {
  CameraModel c = sim::default_camera(w, h, r.uniform(50.0, 90.0));
  c.fy = c.fx * r.uniform(0.97, 1.03);
  c.cx += r.uniform(-5, 5);
  c.cy += r.uniform(-5, 5);
  c.k1 = r.uniform(-0.15, 0.0);
  c.k2 = r.uniform(0.0, 0.03);
  c.p1 = r.uniform(-0.002, 0.002);
  c.p2 = r.uniform(-0.002, 0.002);
  return c;
}

inline Extrinsics random_extrinsics(sim::Random& r, double max_tilt_deg) {
  Extrinsics e;
  e.x = r.uniform(-0.3, 0.3);
  e.y = r.uniform(-0.1, 0.1);
  e.z = r.uniform(0.08, 0.5);
  e.roll = r.uniform(-max_tilt_deg, max_tilt_deg) * M_PI / 180;
  e.pitch = r.uniform(-max_tilt_deg, max_tilt_deg) * M_PI / 180;
  e.yaw = r.uniform(-M_PI, M_PI);
  return e;
}

}  // namespace planarvo::test
