// What the tracker benchmarks simulate: a texture seen by a camera on a robot that drives a
// profile, as `key=value` arguments shared by bench_track accuracy and bench_ecc. Header-only
// (each bench/*.cpp is its own program).
#pragma once
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "bench_args.h"
#include "core/extrinsics.h"
#include "sim/simulator.h"

namespace planarvo::bench {

inline double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

inline std::string texture_path(const std::string& name) {
  return std::string(PLANARVO_SHARED_DIR) + "/data/textures/" + name;
}

inline std::vector<std::string> all_textures() {
  return {"aerial_asphalt_01.png", "aerial_ground_rock.png", "anti_skid_tiles.png", "anti_slip_concrete.png",
          "asphalt_01.png", "asphalt_02.png", "black_painted_planks.png", "blue_floor_tiles_01.png",
          "brick_floor.png", "brown_mud_rocks_01.png", "brushed_concrete.png", "skimage_brick.png",
          "skimage_grass.png", "skimage_gravel.png"};
}

inline std::string describe(const Extrinsics& e) {
  char b[160];
  std::snprintf(b, sizeof b, "(%.4f, %.4f, %.4f m, %.1f, %.1f, %.1f deg)", e.x, e.y, e.z, e.roll * 180 / M_PI,
                e.pitch * 180 / M_PI, e.yaw * 180 / M_PI);
  return b;
}

// The camera on the robot, its field of view, the drive's limits and the noise.
struct Scene {
  int config = 1;        // the paper's configuration (sim::paper_configuration), unless `ext`
  bool has_ext = false;
  Extrinsics ext;        // ext=x,y,z,roll,pitch,yaw (m, deg)
  double fov = 80.0, speed = 0.8, turn = 1.5, radius = 0.0, noise = 1.0;
  int supersampling = 3;  // ss=N: the renderer's subsamples per pixel along each axis
  bool mipmap = true;     // mip=0: no prefiltered texture (only the subsamples average)
  bool distortion = true; // dist=0: a pinhole camera (no lens distortion, so no resampling of the noise)
  double readout = 0.0;   // readout=SECONDS: rolling shutter, first row's read to last's (0: global)
  double exposure = 0.0;  // exposure=SECONDS: motion blur over this long before each row's read
  sim::MotionProfile motion = sim::MotionProfile::Mixed;
  double lamp = 0.0, reflection = 0.0, shadow = 0.0;  // the light fixed to the camera (sim::Options)
  double gain_variation = 0.05;  // gain=A: the camera's slow gain and offset change (sim::Options)
  // A car's body (sim::Options): lean=S (degrees of roll per degree/s), bumps=DEG (peak pitch),
  // knock=T:DROLL,DPITCH,DZ (s, deg, deg, m).
  double lean = 0.0, bumps_deg = 0.0;
  double knock_time = HUGE_VAL, knock_roll_deg = 0.0, knock_pitch_deg = 0.0, knock_z = 0.0;

  Extrinsics extrinsics() const { return has_ext ? ext : sim::paper_configuration(config); }

  // Takes one key=value argument: config, ext, fov, motion, speed, turn, radius, noise, gain, ss, mip, dist,
  // readout, exposure, lamp, reflection, shadow, lean, bumps, knock. False
  // for another key; exits with a message on a bad value.
  bool parse(const std::string& k, const std::string& v) {
    if (k == "config") {
      config = std::atoi(v.c_str());
      if (config < 1 || config > 3) fail("config must be 1, 2 or 3");
    } else if (k == "ext") {
      const std::vector<std::string> e = split(v);
      if (e.size() != 6) fail("ext=x,y,z,roll,pitch,yaw (m, deg)");
      const double d = M_PI / 180.0;
      has_ext = true;
      ext = Extrinsics{std::atof(e[0].c_str()), std::atof(e[1].c_str()), std::atof(e[2].c_str()),
                       std::atof(e[3].c_str()) * d, std::atof(e[4].c_str()) * d, std::atof(e[5].c_str()) * d};
    } else if (k == "motion") {
      motion = v == "straight" ? sim::MotionProfile::Straight
               : v == "circle" ? sim::MotionProfile::Circle
               : v == "spin"   ? sim::MotionProfile::Spin
               : v == "car"    ? sim::MotionProfile::Car
                               : sim::MotionProfile::Mixed;
    } else if (k == "fov") {
      fov = std::atof(v.c_str());
    } else if (k == "speed") {
      speed = std::atof(v.c_str());
    } else if (k == "turn") {
      turn = std::atof(v.c_str());
    } else if (k == "radius") {
      radius = std::atof(v.c_str());
    } else if (k == "noise") {
      noise = std::atof(v.c_str());
    } else if (k == "gain") {
      gain_variation = std::atof(v.c_str());
    } else if (k == "ss") {
      supersampling = std::atoi(v.c_str());
    } else if (k == "mip") {
      mipmap = std::atoi(v.c_str()) != 0;
    } else if (k == "dist") {
      distortion = std::atoi(v.c_str()) != 0;
    } else if (k == "lamp") {
      lamp = std::atof(v.c_str());
    } else if (k == "reflection") {
      reflection = std::atof(v.c_str());
    } else if (k == "shadow") {
      shadow = std::atof(v.c_str());
    } else if (k == "readout") {
      readout = std::atof(v.c_str());
    } else if (k == "exposure") {
      exposure = std::atof(v.c_str());
    } else if (k == "lean") {
      lean = std::atof(v.c_str());
    } else if (k == "bumps") {
      bumps_deg = std::atof(v.c_str());
    } else if (k == "knock") {
      const size_t colon = v.find(':');
      const std::vector<std::string> d = split(colon == std::string::npos ? "" : v.substr(colon + 1));
      if (colon == std::string::npos || d.size() != 3) fail("knock=T:DROLL,DPITCH,DZ (s, deg, deg, m)");
      knock_time = std::atof(v.substr(0, colon).c_str());
      knock_roll_deg = std::atof(d[0].c_str());
      knock_pitch_deg = std::atof(d[1].c_str());
      knock_z = std::atof(d[2].c_str());
    } else {
      return false;
    }
    return true;
  }

  sim::Options options(const std::string& texture, double seconds, int width, int height, uint64_t seed) const {
    sim::Options so;
    so.texture = texture_path(texture);
    so.camera = sim::default_camera(width, height, fov);
    if (!distortion) {
      so.camera.k1 = so.camera.k2 = 0.0;
      so.camera.fx = so.camera.fy = 0.5 * width / std::tan(0.5 * fov * M_PI / 180.0);
    }
    so.seconds = seconds;
    so.seed = seed;
    so.motion = motion;
    so.max_speed = speed;
    so.max_turn_rate = turn;
    so.min_turn_radius = radius;
    so.pixel_noise = noise;
    so.gain_variation = gain_variation;
    so.extrinsics = extrinsics();
    so.supersampling = supersampling;
    so.mipmap = mipmap;
    so.lamp_falloff = lamp;
    so.reflection = reflection;
    so.shadow = shadow;
    so.readout_time = readout;
    so.exposure_time = exposure;
    so.camera.rolling_shutter_readout = readout;
    so.camera.exposure_time = exposure;
    so.lean = lean;
    so.bumps = bumps_deg * M_PI / 180.0;
    so.knock_time = knock_time;
    so.knock_roll = knock_roll_deg * M_PI / 180.0;
    so.knock_pitch = knock_pitch_deg * M_PI / 180.0;
    so.knock_z = knock_z;
    return so;
  }

  std::string summary() const {
    char r[64] = "";
    if (radius > 0) std::snprintf(r, sizeof r, ", turning radius >= %.1f m", radius);
    char b[320];
    std::snprintf(b, sizeof b, "camera %s, fov %.0f deg; %s motion up to %.2f m/s and %.2f rad/s%s; noise %.1f grey levels",
                  describe(extrinsics()).c_str(), fov, sim::motion_profile_name(motion), speed, turn, r, noise);
    std::string out = b;
    if (readout > 0 || exposure > 0) {
      char c[96];
      std::snprintf(c, sizeof c, "; rolling shutter readout %.1f ms, exposure %.1f ms", readout * 1e3, exposure * 1e3);
      out += c;
    }
    if (lamp > 0 || reflection > 0 || shadow > 0) {
      char l[128];
      std::snprintf(l, sizeof l, "; lamp falloff %.2f, reflection %.0f, shadow %.2f", lamp, reflection, shadow);
      out += l;
    }
    if (lean != 0 || bumps_deg != 0 || std::isfinite(knock_time)) {
      char l[160];
      std::snprintf(l, sizeof l, "; body lean %.3f deg per deg/s, bumps %.1f deg", lean, bumps_deg);
      out += l;
      if (std::isfinite(knock_time)) {
        std::snprintf(l, sizeof l, ", knock at %.1f s by %.2f, %.2f deg, %.1f mm", knock_time, knock_roll_deg,
                      knock_pitch_deg, knock_z * 1e3);
        out += l;
      }
    }
    return out;
  }

  [[noreturn]] static void fail(const char* what) {
    std::fprintf(stderr, "%s\n", what);
    std::exit(2);
  }
};

// Frame k of a simulated sequence as the camera gives it: rendered as sim::render_frame sees it
// (each row at its read time, averaged over the exposure), then the camera's gain, offset and
// noise, seeded per frame (every benchmark sees the same frames).
inline cv::Mat camera_frame(sim::Renderer& renderer, const sim::Options& so, const sim::Trajectory& traj,
                            const std::vector<sim::Exposure>& exposure, size_t k,
                            const sim::Lighting& lighting = {}) {
  cv::Mat clean = sim::render_frame(renderer, so, traj, k);
  sim::apply_lighting(lighting, clean);
  return sim::apply_camera(clean, exposure[k], so.pixel_noise, sim::derive_seed(so.seed, 1000 + k));
}

// Every frame of a sequence, rendered once into memory.
inline std::vector<cv::Mat> render_sequence(ocl::Runtime& rt, const sim::Options& so, const sim::Trajectory& traj) {
  const std::vector<sim::Exposure> exposure = sim::exposure_series(so, traj.t);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  std::vector<cv::Mat> frames;
  const sim::Lighting lighting = sim::camera_lighting(so);
  for (size_t k = 0; k < traj.t.size(); ++k) frames.push_back(camera_frame(renderer, so, traj, exposure, k, lighting));
  return frames;
}

}  // namespace planarvo::bench
