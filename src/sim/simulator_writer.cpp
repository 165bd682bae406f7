// simulate(): a whole data set in the layout of docs/formats.md, written with the
// writers of formats.h.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "io/formats.h"
#include "io/yaml_writer.h"
#include "ocl/runtime.h"
#include "sim/frame_finisher.h"
#include "sim/simulator.h"

namespace planarvo::sim {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void report(const Options& o, double fraction, const char* stage) {
  if (o.progress && !o.progress(fraction, stage))
    throw Error(ErrorCode::Cancelled, std::string("simulation cancelled while ") + stage);
}

// The options a data set was made with, for reproducing it (not read by planarvo).
void write_simulation_yaml(const std::string& path, const Options& o, const Eigen::Vector2d& texel) {
  io::YamlWriter y;
  y.write("generator", std::string("planarvo simulator"), "generator");
  y.write("texture", o.texture, path + ": texture");
  y.write("texel_size", o.texel_size);
  y.write("texel_size_u", texel.x());
  y.write("texel_size_v", texel.y());
  y.write("seed", std::to_string(o.seed), "seed");
  y.write("motion", std::string(motion_profile_name(o.motion)), "motion");
  y.write("seconds", o.seconds);
  y.write("fps", o.fps);
  y.write("max_speed", o.max_speed);
  y.write("max_turn_rate", o.max_turn_rate);
  y.write("max_acceleration", o.max_acceleration);
  y.write("max_angular_acceleration", o.max_angular_acceleration);
  y.write_flow("start_pose", std::vector<double>{o.start_pose.x, o.start_pose.y, o.start_pose.theta});
  y.write("pixel_noise", o.pixel_noise);
  y.write("gain_variation", o.gain_variation);
  y.write("odometry_noise", o.odometry_noise);
  y.write("odometry_noise_floor", o.odometry_noise_floor);
  y.write("wheel_base", o.wheel_base);
  y.write("readout_time", o.readout_time);
  y.write("exposure_time", o.exposure_time);
  y.write("supersampling", o.supersampling);
  y.write("mipmap", static_cast<int>(o.mipmap));
  y.write("lamp_falloff", o.lamp_falloff);
  y.write("reflection", o.reflection);
  y.write("shadow", o.shadow);
  y.write("lean", o.lean);
  y.write("bumps", o.bumps);
  y.write("bump_spacing", o.bump_spacing);
  y.write("bump_length", o.bump_length);
  if (std::isfinite(o.knock_time))
    y.write_flow("knock", std::vector<double>{o.knock_time, o.knock_roll, o.knock_pitch, o.knock_z});
  y.save(path);
}

}  // namespace

namespace {

// The data set's files besides the images: camera.yaml, the true extrinsics (and the knocked
// ones), ground truth and odometry (TUM), direction labels, the body's attitude.
void write_truth(const Options& options, const Trajectory& tr, const std::filesystem::path& dir) {
  CameraModel camera = options.camera;
  camera.rolling_shutter_readout = options.readout_time;
  camera.exposure_time = options.exposure_time;
  io::write_camera_yaml((dir / "camera.yaml").string(), camera);
  ExtrinsicsEstimate gt;
  gt.value = options.extrinsics;
  gt.method = "simulator";
  gt.notes = "ground truth of a simulated data set (seed " + std::to_string(options.seed) + ")";
  io::write_extrinsics_yaml((dir / "extrinsics_gt.yaml").string(), gt);
  std::vector<io::StampedPose> truth, odometry;
  std::vector<io::DirectionLabel> labels;
  for (size_t k = 0; k < tr.t.size(); ++k) {
    truth.push_back({tr.t[k], tr.pose[k]});
    odometry.push_back({tr.t[k], tr.odometry[k]});
    if (k > 0) labels.push_back({tr.t[k], tr.direction[k - 1]});
  }
  io::write_tum((dir / "groundtruth.txt").string(), truth);
  io::write_tum((dir / "odometry.txt").string(), odometry);
  io::write_direction((dir / "direction.txt").string(), labels);
  if (options.lean != 0.0 || options.bumps != 0.0) {
    // The body's true attitude relative to the local ground plane, in track --plane-out's format.
    std::vector<io::PlaneAttitude> plane;
    for (size_t k = 0; k < tr.t.size(); ++k) {
      const BodyAttitude a = body_attitude(options, tr, tr.t[k]);
      plane.push_back({tr.t[k], a.roll, a.pitch, 0.0, 0.0});
    }
    io::write_plane((dir / "plane.txt").string(), plane);
  }
  if (std::isfinite(options.knock_time)) {
    ExtrinsicsEstimate knocked = gt;
    knocked.value = knocked_extrinsics(options);
    knocked.notes = "ground truth after the knock at t = " + std::to_string(options.knock_time) + " s (seed " +
                    std::to_string(options.seed) + ")";
    io::write_extrinsics_yaml((dir / "extrinsics_knocked.yaml").string(), knocked);
  }
}

}  // namespace

void simulate(ocl::Runtime& runtime, const Options& options, const std::string& out_dir,
              SimulationStats* stats) {
  SimulationStats st;
  auto t0 = Clock::now();
  validate(options);
  if (options.texture.empty()) throw_invalid_argument("simulator options: no texture given");
  if (out_dir.empty()) throw_invalid_argument("simulate: no output directory given");
  if (!std::filesystem::is_regular_file(options.texture))
    throw_invalid_input(options.texture + ": no such file (the simulator's texture)");
  const cv::Mat texture = cv::imread(options.texture, cv::IMREAD_GRAYSCALE);
  if (texture.empty())
    throw_invalid_input(options.texture + ": cannot be read as an image (the simulator's texture)");

  report(options, 0.0, "setting up");
  const Trajectory tr = generate_trajectory(options);
  // The renderer (its kernel program) before the directory: a device that cannot have the
  // program (e.g. no prebuilt binary of it) leaves nothing behind.
  Renderer renderer(runtime, texture, options);
  const std::vector<Exposure> exposure = exposure_series(options, tr.t);
  const Lighting lighting = camera_lighting(options);

  namespace fs = std::filesystem;
  const fs::path dir(out_dir), images = dir / "images";
  std::error_code ec;
  fs::create_directories(images, ec);
  if (ec || !fs::is_directory(images))
    throw Error(ErrorCode::Io, images.string() + ": cannot create the directory (" + ec.message() + ")");
  st.setup = seconds_since(t0);

  t0 = Clock::now();
  write_truth(options, tr, dir);
  write_simulation_yaml((dir / "simulation.yaml").string(), options, renderer.texel());
  st.write += seconds_since(t0);

  // The device renders frame k + 1 while worker threads finish frame k (frame_finisher.h): one
  // thread of the two cores' is enough to keep up with the render, a second overlaps the render's
  // host side.
  std::vector<io::FrameEntry> frames;
  const size_t n = tr.t.size();
  {
    FrameFinisher finisher(options, lighting, exposure, 2, 4);
    for (size_t k = 0; k < n; ++k) {
      report(options, static_cast<double>(k) / static_cast<double>(n), "rendering");
      t0 = Clock::now();
      cv::Mat clean = render_frame(renderer, options, tr, k);
      st.render += seconds_since(t0);
      char name[32];
      std::snprintf(name, sizeof name, "images/%06zu.png", k);
      finisher.submit(k, std::move(clean), (dir / name).string());
      frames.push_back({tr.t[k], name, 0});
    }
    finisher.finish();
    st.camera = finisher.camera_seconds();
    st.write += finisher.write_seconds();
  }
  t0 = Clock::now();
  io::write_frames((dir / "frames.txt").string(), frames);
  st.write += seconds_since(t0);
  st.frames = static_cast<int64_t>(n);
  if (options.progress) options.progress(1.0, "done");  // too late to cancel
  if (stats) *stats = st;
}

}  // namespace planarvo::sim
