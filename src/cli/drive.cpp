// The simulated drive on the command line (simulate's options) and what a drive looks like
// against its ground truth: shared by `planarvo simulate`, `info` and `demo`.
#include "drive.h"

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace planarvo::cli {

namespace fs = std::filesystem;
constexpr double kDeg = M_PI / 180.0;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The built-in texture: installed beside the tool (../share/planarvo/textures), else the source
// tree's copy.
std::string default_texture() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share/planarvo/textures/asphalt_01.png";
    if (fs::exists(installed)) return installed.string();
  }
  if (fs::exists(PLANARVO_INSTALLED_TEXTURE)) return PLANARVO_INSTALLED_TEXTURE;
  return PLANARVO_DEFAULT_TEXTURE;
}

std::vector<OptionSpec> simulate_options() {
  std::vector<OptionSpec> s = {
      {"out", "DIR", "output data set directory (created)", ""},
      {"texture", "FILE", "ground photograph (grey or colour image)", "built-in asphalt_01.png"},
      {"texel", "METRES", "size of one texture pixel on the ground", "0.0004"},
      {"extrinsics", "x,y,z,roll,pitch,yaw", "camera on the robot: metres and degrees",
       "0.2441,-0.0185,0.1787,12.4,17.6,-9.2"},
      {"seconds", "S", "duration", "10"},
      {"fps", "F", "frame rate", "30"},
      {"seed", "N", "random seed (same seed, same data set)", "1"},
      force_option(),
      {"motion", "KIND", "mixed | straight | circle | spin | car", "mixed"},
      {"min-turn-radius", "M", "car: the tightest turn, metres (0: limited by --max-turn-rate only)", "0"},
      {"max-speed", "M/S", "peak linear speed", "0.8"},
      {"max-turn-rate", "RAD/S", "peak angular speed", "1.5"},
      {"noise", "SIGMA", "pixel noise standard deviation, grey levels", "1"},
      {"gain-variation", "REL", "amplitude of slow camera gain changes", "0.05"},
      {"odometry-noise", "REL", "wheel odometry error per unit of wheel travel", "0.01"},
      {"readout-time", "SECONDS", "rolling shutter: first row's read to last row's, at most 1/fps; written to "
       "camera.yaml as rolling_shutter_readout (0: global shutter)", "0"},
      {"exposure", "SECONDS", "exposure time: each row averages the moving ground over this long before it is read "
       "(motion blur), at most 1/fps; written to camera.yaml as exposure_time", "0"},
      {"lamp", "F", "a camera-mounted lamp: the darkest corner gets 1 - F of the light (0..0.95)", "0 (even light)"},
      {"reflection", "GREY", "the lamp's reflection on a glossy floor: peak grey levels added (saturates)", "0"},
      {"shadow", "F", "the robot's shadow over the image's bottom: fraction of light taken (0..0.95)", "0"},
      {"lean", "DEG_PER_DEG_S", "a car's body rolls with the yaw rate: degrees of roll per degree/s (the paper's "
       "car: -0.07); writes the true attitude to plane.txt", "0"},
      {"bumps", "DEG", "speed bumps every 10 m driven: the body's peak pitch, degrees; writes plane.txt", "0"},
      {"knock", "T:DROLL,DPITCH,DZ", "the camera's mounting is knocked at T seconds: roll and pitch change by "
       "degrees, the height by metres; writes extrinsics_knocked.yaml", "none"},
      {"width", "PX", "image width", "640"},
      {"height", "PX", "image height", "480"},
      {"fov", "DEG", "horizontal field of view", "80"},
      {"distortion", "k1,k2,p1,p2,k3", "lens distortion (OpenCV model)", "-0.12,0.03,0,0,0"},
      {"supersampling", "N", "N x N samples per pixel (plus mip-mapping)", "2"},
      roi_option("the whole image; written to camera.yaml. A camera that sees the horizon needs one that leaves "
                 "it out"),
      {"quiet", "", "no progress bar", ""},
      {"help", "", "show this help", ""},
  };
  for (auto& d : device_options()) s.push_back(d);
  return s;
}

// Fills sim options from the command line over the library's defaults.
void apply_simulate_args(const Args& a, planarvo_sim_options* o, std::string* texture) {
  *texture = a.get("texture", default_texture());
  o->texture = texture->c_str();
  o->texel_size = a.get_double("texel", o->texel_size);
  if (a.has("extrinsics")) {
    const auto v = a.get_doubles("extrinsics", 6);
    o->extrinsics = {v[0], v[1], v[2], v[3] * kDeg, v[4] * kDeg, v[5] * kDeg};
  }
  o->accept_unusual_extrinsics = a.has("force") ? 1 : 0;
  o->seconds = a.get_double("seconds", o->seconds);
  o->fps = a.get_double("fps", o->fps);
  const long long seed = a.get_int("seed", static_cast<long long>(o->seed));
  if (seed < 0) throw UsageError("--seed must be non-negative");
  o->seed = static_cast<uint64_t>(seed);
  const std::string motion = a.get("motion", "mixed");
  if (motion == "mixed") o->motion = PLANARVO_MOTION_MIXED;
  else if (motion == "straight") o->motion = PLANARVO_MOTION_STRAIGHT;
  else if (motion == "circle") o->motion = PLANARVO_MOTION_CIRCLE;
  else if (motion == "spin") o->motion = PLANARVO_MOTION_SPIN;
  else if (motion == "car") o->motion = PLANARVO_MOTION_CAR;
  else throw UsageError("--motion must be mixed, straight, circle, spin or car, not \"" + motion + "\"");
  o->min_turn_radius = a.get_double("min-turn-radius", o->min_turn_radius);
  o->max_speed = a.get_double("max-speed", o->max_speed);
  o->max_turn_rate = a.get_double("max-turn-rate", o->max_turn_rate);
  o->pixel_noise = a.get_double("noise", o->pixel_noise);
  o->gain_variation = a.get_double("gain-variation", o->gain_variation);
  o->lamp_falloff = a.get_double("lamp", o->lamp_falloff);
  o->reflection = a.get_double("reflection", o->reflection);
  o->shadow = a.get_double("shadow", o->shadow);
  o->lean = a.get_double("lean", o->lean);
  o->bumps = a.get_double("bumps", o->bumps / kDeg) * kDeg;
  if (a.has("knock")) {
    const std::vector<double> d = a.get_stamped_doubles("knock", 3, &o->knock_time);
    if (!(o->knock_time >= 0)) throw UsageError("option --knock: the time must be >= 0 seconds");
    o->knock_roll = d[0] * kDeg;
    o->knock_pitch = d[1] * kDeg;
    o->knock_z = d[2];
  }
  o->odometry_noise = a.get_double("odometry-noise", o->odometry_noise);
  o->readout_time = a.get_double("readout-time", o->readout_time);
  o->exposure_time = a.get_double("exposure", o->exposure_time);
  o->supersampling = static_cast<int32_t>(a.get_int("supersampling", o->supersampling));
  planarvo_camera& c = o->camera;
  if (a.has("width") || a.has("height") || a.has("fov")) {
    const long long w = a.get_int("width", c.width), h = a.get_int("height", c.height);
    if (w < 8 || h < 8 || w > 16384 || h > 16384) throw UsageError("--width/--height must be 8..16384");
    const double fov = a.get_double("fov", 80.0);
    if (!(fov > 1 && fov < 170)) throw UsageError("--fov must be between 1 and 170 degrees");
    check(planarvo_sim_default_camera(static_cast<int32_t>(w), static_cast<int32_t>(h), fov, &c));
  }
  if (a.has("distortion")) {
    const auto d = a.get_doubles("distortion", 5);
    c.k1 = d[0]; c.k2 = d[1]; c.p1 = d[2]; c.p2 = d[3]; c.k3 = d[4];
  }
  if (const std::optional<planarvo_region> r = parse_roi(a)) c.roi = *r;
}

DriveSummary summarise(planarvo_dataset* ds, int64_t n) {
  DriveSummary s;
  std::vector<planarvo_frame_data> f(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) check(planarvo_dataset_frame_data(ds, i, &f[static_cast<size_t>(i)]));
  double sq = 0;
  int steps = 0;
  s.has_odometry = n > 1 && f[0].has_odometry && f[0].has_groundtruth;
  for (size_t i = 1; i < f.size(); ++i) {
    const auto &a = f[i - 1], &b = f[i];
    const double dt = b.timestamp - a.timestamp;
    if (a.has_groundtruth && b.has_groundtruth) {
      const double d = std::hypot(b.groundtruth.x - a.groundtruth.x, b.groundtruth.y - a.groundtruth.y);
      const double dth = std::remainder(b.groundtruth.theta - a.groundtruth.theta, 2 * M_PI);
      s.distance += d;
      s.peak_speed = std::max(s.peak_speed, d / dt);
      s.peak_turn = std::max(s.peak_turn, std::abs(dth) / dt);
      if (a.has_odometry && b.has_odometry) {
        // Relative motion in the frame of a, for both, compared.
        const planarvo_se2 g = relative(a.groundtruth, b.groundtruth), o = relative(a.odometry, b.odometry);
        sq += (g.x - o.x) * (g.x - o.x) + (g.y - o.y) * (g.y - o.y);
        ++steps;
      }
    }
    if (b.has_direction) {
      if (b.direction > 0) ++s.forward;
      else if (b.direction < 0) ++s.backward;
      else ++s.still;
    }
  }
  if (s.has_odometry && f.back().has_odometry && f.back().has_groundtruth) {
    // Both trajectories relative to their first pose.
    const planarvo_se2 g = relative(f.front().groundtruth, f.back().groundtruth);
    const planarvo_se2 o = relative(f.front().odometry, f.back().odometry);
    s.odo_end_error = std::hypot(g.x - o.x, g.y - o.y);
    s.odo_heading_error = std::abs(std::remainder(g.theta - o.theta, 2 * M_PI));
    s.odo_rms_step = steps ? std::sqrt(sq / steps) : 0;
  }
  return s;
}

}  // namespace planarvo::cli
