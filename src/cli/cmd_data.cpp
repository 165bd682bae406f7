// `planarvo simulate`, `planarvo info` and `planarvo demo`: data sets in and out.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

#include "common.h"

namespace planarvo::cli {
namespace {

constexpr double kDeg = M_PI / 180.0;
namespace fs = std::filesystem;

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
      {"force", "", "accept extrinsics outside the plausible ranges (an offset over 20 m, a height over 5 m, an angle over a turn): an unusual rig, not a unit mistake", ""},
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

// What a trajectory and its wheel odometry look like against ground truth.
struct DriveSummary {
  double distance = 0, peak_speed = 0, peak_turn = 0;
  int forward = 0, backward = 0, still = 0;
  bool has_odometry = false;
  double odo_end_error = 0, odo_heading_error = 0, odo_rms_step = 0;
};

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

// A bag's topics, before it is opened as a data set (which needs the right topics).
struct BagTopic {
  std::string name, type, count;  // count "" when the file does not say
  std::string described() const { return name + " (" + type + (count.empty() ? "" : ", " + count + " messages") + ")"; }
};

std::vector<BagTopic> bag_topics(const std::string& path) {
  size_t needed = 0;
  check(planarvo_bag_topics(path.c_str(), nullptr, 0, &needed));
  std::string list(needed, '\0');
  check(planarvo_bag_topics(path.c_str(), list.data(), list.size(), nullptr));
  std::vector<BagTopic> topics;
  size_t at = 0;
  for (size_t end = list.find('\n'); end != std::string::npos; at = end + 1, end = list.find('\n', at)) {
    const std::string line = list.substr(at, end - at);
    const size_t a = line.find('\t'), b = line.rfind('\t');
    const std::string count = line.substr(b + 1);
    topics.push_back({line.substr(0, a), line.substr(a + 1, b - a - 1), count == "-1" ? "" : count});
  }
  return topics;
}

void print_bag_topics(const std::string& path, const std::vector<BagTopic>& topics) {
  std::printf("topics of %s\n", path.c_str());
  for (const BagTopic& t : topics)
    std::printf("  %-32s %-32s %s\n", t.name.c_str(), t.type.c_str(),
                t.count.empty() ? "" : (t.count + " messages").c_str());
}

// For a bag, which topic each of the data set's streams comes from: the one given (--...-topic),
// else the only candidate the library picked, else the candidates and the option that picks one.
void print_bag_streams(const std::vector<BagTopic>& topics, const Args& args) {
  const auto of_type = [&](std::initializer_list<const char*> types) {
    std::vector<BagTopic> out;
    for (const BagTopic& t : topics)
      for (const char* type : types)
        if (t.type == type) {
          out.push_back(t);
          break;
        }
    return out;
  };
  const auto find = [&](const std::string& name) {
    for (const BagTopic& t : topics)
      if (t.name == name) return t.described();
    return name;
  };
  const auto line = [&](const char* label, const std::string& option, std::initializer_list<const char*> types,
                        bool picks_the_only_one) {
    const std::vector<BagTopic> candidates = of_type(types);
    std::string text;
    if (args.has(option)) {
      text = find(args.get(option));
    } else if (picks_the_only_one && candidates.size() == 1) {
      text = candidates[0].described() + ", the only one";
    } else if (candidates.empty()) {
      text = "none in the bag";
    } else {
      text = "not read: give --" + option + " (";
      for (size_t i = 0; i < candidates.size(); ++i) text += (i ? ", " : "") + candidates[i].described();
      text += ")";
    }
    std::printf("  %-11s %s\n", label, text.c_str());
  };
  line("images", "image-topic", {"sensor_msgs/Image", "sensor_msgs/CompressedImage", "sensor_msgs/msg/Image",
                                 "sensor_msgs/msg/CompressedImage"}, true);
  if (args.has("camera"))
    std::printf("  %-11s %s\n", "camera from", args.get("camera").c_str());
  else
    line("camera from", "camera-info-topic", {"sensor_msgs/CameraInfo", "sensor_msgs/msg/CameraInfo"}, true);
  line("odometry", "odom-topic", {"nav_msgs/Odometry", "nav_msgs/msg/Odometry"}, false);
  line("groundtruth", "groundtruth-topic", {"nav_msgs/Odometry", "nav_msgs/msg/Odometry"}, false);
}

// topics: a bag's (bag_topics), empty for a folder.
void print_dataset(planarvo_dataset* ds, const std::string& dir, const Args& args,
                   const std::vector<BagTopic>& topics) {
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  check(planarvo_dataset_info_get(ds, &info));
  const auto& c = info.camera;
  const double span = info.last_timestamp - info.first_timestamp;
  std::printf("%s %s\n", info.is_bag ? "bag" : "data set", dir.c_str());
  std::printf("  frames      %lld over %.3f s (%.2f fps)\n", static_cast<long long>(info.frame_count), span,
              info.frame_count > 1 ? static_cast<double>(info.frame_count - 1) / span : 0.0);
  if (info.is_bag)
    std::printf("  first frame %lld.%09lld s (its stamp; times are counted from it)\n",
                static_cast<long long>(info.time_origin_ns / 1000000000),
                static_cast<long long>(info.time_origin_ns % 1000000000));
  std::printf("  camera      %dx%d, fx %.2f fy %.2f cx %.2f cy %.2f, distortion %.4g %.4g %.4g %.4g %.4g\n",
              c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3);
  if (c.roi.width > 0)
    std::printf("  region      x %d, y %d, %dx%d pixels (region of interest)\n", c.roi.x, c.roi.y, c.roi.width,
                c.roi.height);
  else
    std::printf("  region      the whole image\n");
  if (c.rolling_shutter_readout > 0)
    std::printf("  shutter     rolling, %.3f ms from the first row's read to the last's\n",
                c.rolling_shutter_readout * 1e3);
  if (c.exposure_time > 0) std::printf("  exposure    %.3f ms\n", c.exposure_time * 1e3);
  if (info.is_bag) {
    print_bag_streams(topics, args);  // which topic each stream comes from, or which could
  } else {
    std::printf("  odometry    %s\n  direction   %s\n  groundtruth %s\n", info.has_odometry ? "yes" : "no",
                info.has_direction ? "yes" : "no", info.has_groundtruth ? "yes" : "no");
  }
  auto ext = [](const char* label, int has, const planarvo_extrinsics& e) {
    if (!has) {
      std::printf("  %-11s no\n", label);
      return;
    }
    std::printf("  %-11s x %.1f mm, y %.1f mm, z %.1f mm, roll %.2f deg, pitch %.2f deg, yaw %.2f deg\n", label,
                e.x * 1e3, e.y * 1e3, e.z * 1e3, e.roll / kDeg, e.pitch / kDeg, e.yaw / kDeg);
  };
  ext("extrinsics", info.has_extrinsics, info.extrinsics);
  ext("true extr.", info.has_extrinsics_gt, info.extrinsics_gt);
  if (info.has_groundtruth) {
    const DriveSummary s = summarise(ds, info.frame_count);
    std::printf("  drive       %.2f m, peak %.2f m/s and %.2f rad/s; intervals: %d forward, %d backward, "
                "%d without linear motion\n",
                s.distance, s.peak_speed, s.peak_turn, s.forward, s.backward, s.still);
  }
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  const auto specs = simulate_options();
  Args args(specs, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo simulate --out DIR [options]\n\n"
                "Renders a downward-looking camera on a differential-drive robot over a textured ground\n"
                "plane, with exact ground truth, in the data set layout planarvo reads.\n\n%s",
                format_options(specs).c_str());
    return kExitOk;
  }
  if (!args.positionals().empty()) throw UsageError("unexpected argument " + args.positionals()[0]);
  if (!args.has("out")) throw UsageError("--out DIR is required");
  planarvo_sim_options o;
  planarvo_sim_options_init(&o);
  std::string texture;
  apply_simulate_args(args, &o, &texture);
  ContextPtr ctx = make_context(args);
  Progress progress(!args.has("quiet"));
  o.progress = &Progress::callback;
  o.progress_user_data = &progress;
  const auto t0 = std::chrono::steady_clock::now();
  check(planarvo_simulate(ctx.get(), &o, args.get("out").c_str()));
  progress.finish();
  std::printf("simulated %.1f s at %.0f fps (%dx%d) over %s into %s in %.1f s on %s\n", o.seconds, o.fps,
              o.camera.width, o.camera.height, texture.c_str(), args.get("out").c_str(), seconds_since(t0),
              device_name(ctx.get()).c_str());
  return kExitOk;
}

int cmd_info(int argc, char** argv) {
  const std::vector<OptionSpec> specs = {
      {"video", "FILE", "a video file standing in for images/ and frames.txt", ""},
      {"verify", "", "decode every image now (sizes, unreadable files)", ""},
      {"quiet", "", "no progress bar", ""},
      {"help", "", "show this help", ""}};
  std::vector<OptionSpec> all = specs;
  for (auto& b : bag_options()) all.push_back(b);
  Args args(all, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo info DATASET [--verify] [--video FILE]\n"
                "       planarvo info BAG [--image-topic T] [--camera-info-topic T | --camera FILE] [--odom-topic T]\n\n"
                "Reads a data set (docs/formats.md: camera.yaml, frames.txt, images/, optional odometry.txt,\n"
                "direction.txt, groundtruth.txt, extrinsics.yaml), checks it and prints what it holds.\n\n%s",
                format_options(all).c_str());
    return kExitOk;
  }
  args.expect_positionals(1, "DATASET, the data set folder or a bag");
  std::vector<BagTopic> topics;  // read once, for the list and the streams
  if (is_bag_path(args.positionals()[0])) {
    topics = bag_topics(args.positionals()[0]);
    print_bag_topics(args.positionals()[0], topics);
  }
  Progress progress(!args.has("quiet"));
  DatasetPtr ds = open_dataset(args.positionals()[0], args, args.has("verify"), &progress);
  progress.finish();
  print_dataset(ds.get(), args.positionals()[0], args, topics);
  if (args.has("verify")) std::printf("  every image decoded and checked\n");
  return kExitOk;
}

namespace {

// The demo's accuracy table: the simulated wheel odometry's and the tracker's against ground truth.
void print_demo_accuracy(const DriveSummary& s, const TrackRun& run, double odometry_noise) {
  std::printf("\n   accuracy against ground truth       end-point error     heading error   per-frame RMS\n");
  if (s.has_odometry)
    std::printf("   wheel odometry (simulated, %2.0f%%)   %8.2f mm (%5.3f%%) %9.3f deg %11.4f mm\n",
                odometry_noise * 100, s.odo_end_error * 1e3, 100 * s.odo_end_error / std::max(s.distance, 1e-9),
                s.odo_heading_error / kDeg, s.odo_rms_step * 1e3);
  if (run.has_accuracy) {
    const planarvo_motion_accuracy& a = run.accuracy;
    std::printf("   visual odometry (planarvo)          %8.2f mm (%5.3f%%) %9.3f deg %11.4f mm\n",
                a.endpoint_error * 1e3, 100 * a.endpoint_drift, a.endpoint_heading / kDeg, a.rms_translation * 1e3);
    std::printf("   visual odometry velocity slopes: linear %.4f, angular %.4f; gross errors (> 1 mm): %d\n",
                a.slope_linear, a.slope_angular, a.gross_errors);
  }

}

// The demo's calibration table: each parameter estimated, true, its error and sigma.
void print_demo_calibration(planarvo_status cs, const planarvo_camera_calibration_result& cr,
                            const planarvo_extrinsics& truth) {
  if (cs == PLANARVO_ERROR_FAILED) {
    std::printf("   not determined: %s\n", cr.reason);
  } else {
    const planarvo_extrinsics& t = truth;
    const planarvo_extrinsics& e = cr.extrinsics;
    const double est[6] = {e.x, e.y, e.z, e.roll, e.pitch, e.yaw}, tru[6] = {t.x, t.y, t.z, t.roll, t.pitch, t.yaw};
    std::printf("   %-6s %12s %12s %10s %10s\n", "", "estimated", "true", "error", "sigma");
    for (int i = 0; i < 6; ++i) {
      const double k = i < 3 ? 1e3 : 1 / kDeg;
      std::printf("   %-6s %8.3f %-3s %8.3f %-3s %10.3f %10.3f\n", planarvo_extrinsics_name(i), est[i] * k, i < 3 ? "mm" : "deg",
                  tru[i] * k, i < 3 ? "mm" : "deg", std::remainder(est[i] - tru[i], 2 * M_PI) * k,
                  std::sqrt(std::max(0.0, cr.covariance[i * 7])) * k);
    }
  }
}

// The demo's drive: the mixed profile has everything the calibration needs (forward, backward,
// arcs, turns in place) from about 6 s on; 7 s keeps the whole demo under 10 s on two cores.
constexpr double kDemoSeconds = 7.0;

}  // namespace

int cmd_demo(int argc, char** argv) {
  std::vector<OptionSpec> specs = simulate_options();
  specs.erase(std::remove_if(specs.begin(), specs.end(), [](const OptionSpec& s) { return s.name == "out"; }),
              specs.end());
  for (OptionSpec& s : specs)
    if (s.name == "seconds") s.fallback = "7";
  specs.insert(specs.begin(), {"out", "DIR", "where to write the simulated data set", "a new folder in $TMPDIR"});
  Args args(specs, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo demo [options]\n\n"
                "The main job on a built-in default: simulates a short drive over a real ground texture,\n"
                "reads it back, tracks it, calibrates the camera from the images and the odometry, and prints\n"
                "the accuracy of both against ground truth.\n\n%s",
                format_options(specs).c_str());
    return kExitOk;
  }
  if (!args.positionals().empty()) throw UsageError("unexpected argument " + args.positionals()[0]);
  std::string out = args.get("out");
  if (out.empty()) {
    const char* tmp = std::getenv("TMPDIR");
    std::string templ = std::string(tmp && *tmp ? tmp : "/tmp") + "/planarvo-demo-XXXXXX";
    if (!mkdtemp(templ.data())) throw ApiError(PLANARVO_ERROR_IO, "cannot create a folder in " + templ);
    out = templ;
  }
  planarvo_sim_options o;
  planarvo_sim_options_init(&o);
  o.seconds = kDemoSeconds;
  std::string texture;
  apply_simulate_args(args, &o, &texture);
  ContextPtr ctx = make_context(args);
  std::printf("planarvo %s demo on %s\n", planarvo_version_string(), device_name(ctx.get()).c_str());
  std::printf("1. simulating a %.0f s drive at %.0f fps, %dx%d, over %s (texel %.2f mm)\n", o.seconds, o.fps,
              o.camera.width, o.camera.height, fs::path(texture).filename().c_str(), o.texel_size * 1e3);
  std::printf("   camera at x %.1f mm, y %.1f mm, height %.1f mm, roll %.1f, pitch %.1f, yaw %.1f deg\n",
              o.extrinsics.x * 1e3, o.extrinsics.y * 1e3, o.extrinsics.z * 1e3, o.extrinsics.roll / kDeg,
              o.extrinsics.pitch / kDeg, o.extrinsics.yaw / kDeg);
  std::fflush(stdout);
  Progress progress(!args.has("quiet"));
  o.progress = &Progress::callback;
  o.progress_user_data = &progress;
  auto t0 = std::chrono::steady_clock::now();
  check(planarvo_simulate(ctx.get(), &o, out.c_str()));
  progress.finish();
  std::printf("   wrote %s in %.1f s\n", out.c_str(), seconds_since(t0));

  std::printf("2. reading the data set back and decoding every image\n");
  std::fflush(stdout);
  t0 = std::chrono::steady_clock::now();
  DatasetPtr ds = open_dataset(out, "", true, &progress);
  progress.finish();
  std::printf("   done in %.1f s\n", seconds_since(t0));
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  check(planarvo_dataset_info_get(ds.get(), &info));
  const DriveSummary s = summarise(ds.get(), info.frame_count);
  std::printf("3. the drive (ground truth): %.2f m, peak %.2f m/s, %.2f rad/s; intervals: %d forward, %d backward,"
              " %d without linear motion\n",
              s.distance, s.peak_speed, s.peak_turn, s.forward, s.backward, s.still);
  std::printf("4. tracking every frame with the true extrinsics\n");
  std::fflush(stdout);
  t0 = std::chrono::steady_clock::now();
  planarvo_tracker_options to;
  planarvo_tracker_options_init(&to);
  const TrackRun run = track_dataset(ctx.get(), ds.get(), info.extrinsics_gt, to, {}, &progress);
  progress.finish();
  // The median frame: a first run's first frames also compile the kernels (once; then cached).
  const double median = median_ms(run);
  const double compiling = run.engine_ms - median * static_cast<double>(run.frames);
  std::printf("   tracked every frame in %.1f s: %lld ok, %lld degraded, %lld lost; engine %.2f ms per frame "
              "(median, %.0f fps)\n",
              seconds_since(t0), static_cast<long long>(run.ok), static_cast<long long>(run.degraded),
              static_cast<long long>(run.lost), median, 1000.0 / median);
  if (compiling > 1000.0)
    std::printf("   (this first run also compiled the tracker's OpenCL kernels: about %.1f s; they are cached now)\n",
                compiling / 1000.0);
  print_demo_accuracy(s, run, o.odometry_noise);

  // 5. The camera's calibration from the images and the wheel odometry alone.
  std::printf("\n5. calibrating the camera from the images and the wheel odometry (planarvo calibrate)\n");
  std::fflush(stdout);
  t0 = std::chrono::steady_clock::now();
  planarvo_camera_calibration_options co;
  planarvo_camera_calibration_options_init(&co);
  planarvo_camera_calibration_result cr{};
  const planarvo_status cs = calibrate_dataset(ctx.get(), ds.get(), &co, &progress, &cr);
  std::printf("   done in %.1f s:\n", seconds_since(t0));
  print_demo_calibration(cs, cr, info.extrinsics_gt);
  std::printf("\nLook at the frames in %s/images; `planarvo info %s` describes the data set.\n", out.c_str(),
              out.c_str());
  return kExitOk;
}

}  // namespace planarvo::cli
