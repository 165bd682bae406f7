// C API: the simulator (src/sim/simulator.h). The defaults of planarvo_sim_options are those of
// sim::Options, so they are stated in one place.
#include <cstring>
#include <string>

#include "capi/convert.h"
#include "capi/handles.h"
#include "capi/status.h"
#include "sim/simulator.h"

using planarvo::capi::guard;
using planarvo::capi::require;

extern "C" {

PLANARVO_API void planarvo_sim_options_init(planarvo_sim_options* o) {
  if (!o) return;
  std::memset(o, 0, sizeof *o);
  const planarvo::sim::Options d;
  o->struct_size = sizeof *o;
  o->texture = nullptr;
  o->texel_size = d.texel_size;
  o->extrinsics = planarvo::capi::to_c(d.extrinsics);
  o->camera = planarvo::capi::to_c(d.camera);
  o->seconds = d.seconds;
  o->fps = d.fps;
  o->seed = d.seed;
  o->motion = PLANARVO_MOTION_MIXED;
  o->max_speed = d.max_speed;
  o->max_turn_rate = d.max_turn_rate;
  o->pixel_noise = d.pixel_noise;
  o->gain_variation = d.gain_variation;
  o->odometry_noise = d.odometry_noise;
  o->supersampling = d.supersampling;
  o->min_turn_radius = d.min_turn_radius;
  o->readout_time = d.readout_time;
  o->exposure_time = d.exposure_time;
  o->lamp_falloff = d.lamp_falloff;
  o->reflection = d.reflection;
  o->shadow = d.shadow;
  o->lean = d.lean;
  o->bumps = d.bumps;
  o->knock_time = d.knock_time;
  o->knock_roll = d.knock_roll;
  o->knock_pitch = d.knock_pitch;
  o->knock_z = d.knock_z;
}

PLANARVO_API planarvo_status planarvo_sim_default_camera(int32_t width, int32_t height, double fov_deg,
                                                         planarvo_camera* camera) {
  return guard([&] {
    require(camera != nullptr, "planarvo_sim_default_camera: camera is NULL");
    require(width >= 8 && height >= 8 && width <= 16384 && height <= 16384,
            "planarvo_sim_default_camera: width and height must be 8..16384");
    require(fov_deg > 1.0 && fov_deg < 170.0, "planarvo_sim_default_camera: fov must be 1..170 degrees");
    *camera = planarvo::capi::to_c(planarvo::sim::default_camera(width, height, fov_deg));
  });
}

PLANARVO_API planarvo_status planarvo_simulate(planarvo_context* context, const planarvo_sim_options* o,
                                               const char* out_directory) {
  return guard([&] {
    require(context != nullptr, "planarvo_simulate: context is NULL");
    require(o != nullptr, "planarvo_simulate: options is NULL");
    require(out_directory != nullptr && *out_directory, "planarvo_simulate: out_directory is NULL or empty");
    planarvo::capi::require_struct_size(o->struct_size,
                                        offsetof(planarvo_sim_options, progress_user_data) + sizeof(void*),
                                        "planarvo_sim_options");
    require(o->texture != nullptr && *o->texture, "planarvo_simulate: options.texture is required");
    planarvo::sim::Options s;
    s.texture = o->texture;
    s.texel_size = o->texel_size;
    s.extrinsics = planarvo::capi::to_cpp(o->extrinsics);
    s.camera = planarvo::capi::to_cpp(o->camera);
    s.seconds = o->seconds;
    s.fps = o->fps;
    s.seed = o->seed;
    switch (planarvo::capi::enum_value(o->motion)) {
      case PLANARVO_MOTION_MIXED: s.motion = planarvo::sim::MotionProfile::Mixed; break;
      case PLANARVO_MOTION_STRAIGHT: s.motion = planarvo::sim::MotionProfile::Straight; break;
      case PLANARVO_MOTION_CIRCLE: s.motion = planarvo::sim::MotionProfile::Circle; break;
      case PLANARVO_MOTION_SPIN: s.motion = planarvo::sim::MotionProfile::Spin; break;
      case PLANARVO_MOTION_CAR: s.motion = planarvo::sim::MotionProfile::Car; break;
      default: require(false, "planarvo_simulate: options.motion is not a planarvo_motion_profile");
    }
    s.max_speed = o->max_speed;
    s.max_turn_rate = o->max_turn_rate;
    if (o->struct_size >= offsetof(planarvo_sim_options, min_turn_radius) + sizeof(double))
      s.min_turn_radius = o->min_turn_radius;
    if (o->struct_size >= offsetof(planarvo_sim_options, readout_time) + sizeof(double))
      s.readout_time = o->readout_time;
    if (o->struct_size >= offsetof(planarvo_sim_options, exposure_time) + sizeof(double))
      s.exposure_time = o->exposure_time;
    if (o->struct_size >= offsetof(planarvo_sim_options, shadow) + sizeof(double)) {
      s.lamp_falloff = o->lamp_falloff;
      s.reflection = o->reflection;
      s.shadow = o->shadow;
    }
    if (o->struct_size >= offsetof(planarvo_sim_options, knock_z) + sizeof(double)) {
      s.lean = o->lean;
      s.bumps = o->bumps;
      s.knock_time = o->knock_time;
      s.knock_roll = o->knock_roll;
      s.knock_pitch = o->knock_pitch;
      s.knock_z = o->knock_z;
    }
    if (o->struct_size >= offsetof(planarvo_sim_options, accept_unusual_extrinsics) + sizeof(int32_t))
      s.accept_unusual_extrinsics = o->accept_unusual_extrinsics != 0;
    s.pixel_noise = o->pixel_noise;
    s.gain_variation = o->gain_variation;
    s.odometry_noise = o->odometry_noise;
    s.supersampling = o->supersampling;
    if (o->progress) {
      const planarvo_progress_fn fn = o->progress;
      void* user = o->progress_user_data;
      s.progress = [fn, user](double f, const char* stage) { return fn(user, f, stage) == 0; };
    }
    planarvo::sim::simulate(*context->runtime, s, out_directory);
  });
}

}  // extern "C"
