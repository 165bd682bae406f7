// The whole camera calibration (calib/pipeline.h: roll and pitch from images, tracking, the graph
// calibration) on simulated data sets written to disk and read back as a user's would be, against
// the simulator's true extrinsics. One row per run (errors and reported sigmas), then per
// parameter the worst error and the RMS of error / sigma over the runs, also with the sigmas
// less the tilt's share (calib/tilt_propagation.h), which is what they were before it.
//
//   bench_calibrate [key=value ...]
//     textures=a.png,b.png   (shared/data/textures)            default asphalt_01.png,anti_skid_tiles.png
//     configs=1,2,3,r1,r2    the paper's configurations; rN: random pose N   default 1,2,3,r1,r2
//     method=odometry|nonholonomic  (nonholonomic: the true height is given)  default odometry
//     seconds=S (20) size=WxH (640x480) odometry_noise=REL (0.02) noise=GREY (1) gain=REL (0.05)
//     seed=N (1) frames=N (roll/pitch frames; 0 = until the map is complete) keep=DIR (keep data sets)
//     list=1 (print the configurations and stop)
//     propagate=0 (the tilt's uncertainty not carried into x, y, z, yaw: PipelineOptions::propagate_tilt)
//
//   bench_calibrate windows [key=value ...]   the paper's statistical form (its Tables 1-3, 5): one
//     long drive (seconds=60), the calibration run on overlapping sub-trajectories of window=20 s
//     every step=5 s, roll and pitch from frames=10 frames of each; mean +- std and the truth per
//     parameter. texture=, config=, method= as above.
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <optional>
#include <vector>

#include <unistd.h>

#include "calib/pipeline.h"
#include "io/dataset/dataset.h"
#include "sim/simulator.h"
#include "bench_args.h"
#include "ocl/runtime.h"

using namespace planarvo;

namespace {

constexpr double kDeg = M_PI / 180.0;

using bench::get;
using bench::split;

Extrinsics config(const std::string& name, uint64_t seed) {
  if (name[0] == 'r') {
    sim::Random r(sim::derive_seed(seed, 500 + std::stoull(name.substr(1))));
    return {r.uniform(-0.3, 0.3), r.uniform(-0.2, 0.2), r.uniform(0.12, 0.3),
            r.uniform(-25, 25) * kDeg, r.uniform(-25, 25) * kDeg, r.uniform(-180, 180) * kDeg};
  }
  return sim::paper_configuration(std::stoi(name));
}

}  // namespace

int windows(const bench::Args& args);

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "windows") return windows(bench::parse_args(argc - 1, argv + 1, "bench_calibrate windows"));
  const auto args = bench::parse_args(argc, argv, "bench_calibrate");
  const std::string shared = PLANARVO_SHARED_DIR;
  const auto textures = split(get(args, "textures", "asphalt_01.png,anti_skid_tiles.png"));
  const auto configs = split(get(args, "configs", "1,2,3,r1,r2"));
  const bool nonholonomic = get(args, "method", "odometry") == "nonholonomic";
  const std::string size = get(args, "size", "640x480");
  const std::string keep = get(args, "keep", "");
  const uint64_t seed = std::stoull(get(args, "seed", "1"));

  ocl::Runtime rt;
  for (const std::string& cfg : configs) {
    const Extrinsics e = config(cfg, seed);
    std::printf("config %-3s x %.4f y %.4f z %.4f m, roll %.2f pitch %.2f yaw %.2f deg\n", cfg.c_str(), e.x, e.y, e.z,
                e.roll / kDeg, e.pitch / kDeg, e.yaw / kDeg);
  }
  if (args.count("list")) return 0;
  std::printf("%-20s %-4s | %7s %7s %7s %7s %7s %7s | %6s %6s %6s %6s %6s %6s | %5s %5s %5s %5s %s\n", "texture", "cfg",
              "dx mm", "dy mm", "dz mm", "dr deg", "dp deg", "dyaw", "sx", "sy", "sz", "sr", "sp", "syaw", "rp s",
              "trk s", "dec s", "all s", "status");
  const char* names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  double worst[6] = {}, nees[6] = {}, nees_alone[6] = {};
  int counted[6] = {}, runs = 0, failed = 0;
  for (const std::string& tex : textures)
    for (const std::string& cfg : configs) {
      sim::Options so;
      so.texture = shared + "/data/textures/" + tex;
      so.camera = sim::default_camera(std::stoi(size.substr(0, size.find('x'))), std::stoi(size.substr(size.find('x') + 1)));
      so.extrinsics = config(cfg, seed);
      so.seconds = std::stod(get(args, "seconds", "20"));
      so.seed = seed + std::hash<std::string>()(tex + cfg) % 1000;
      so.odometry_noise = std::stod(get(args, "odometry_noise", "0.02"));
      so.pixel_noise = std::stod(get(args, "noise", "1"));
      so.gain_variation = std::stod(get(args, "gain", "0.05"));
      const std::filesystem::path dir =
          keep.empty() ? std::filesystem::temp_directory_path() / ("planarvo_bench_calibrate_" + std::to_string(::getpid()))
                       : std::filesystem::path(keep) / (tex.substr(0, tex.find('.')) + "_" + cfg);
      std::filesystem::remove_all(dir);
      sim::simulate(rt, so, dir.string());

      io::Dataset ds(dir.string());
      calib::PipelineOptions po;
      if (nonholonomic) {
        po.graph.method = graph::CalibrationMethod::Nonholonomic;
        po.graph.fix_scale = true;
        po.graph.fixed_scale = so.extrinsics.z;
      }
      if (args.count("frames")) po.roll_pitch.max_frames = std::stoi(get(args, "frames", "0"));
      po.propagate_tilt = get(args, "propagate", "1") != "0";
      const calib::PipelineReport r = calib::calibrate_dataset(rt, ds, po);
      const Extrinsics& t = so.extrinsics;
      const Extrinsics& e = r.extrinsics.value;
      const double err[6] = {e.x - t.x, e.y - t.y, e.z - t.z, e.roll - t.roll, e.pitch - t.pitch,
                             std::remainder(e.yaw - t.yaw, 2 * M_PI)};
      double sd[6], sd_alone[6];  // reported; and without the tilt's share (propagate=0's)
      for (int i = 0; i < 6; ++i) sd[i] = sd_alone[i] = std::sqrt(std::max(0.0, r.extrinsics.covariance(i, i)));
      if (r.tilt_jacobian) {
        const Eigen::Matrix4d share = *r.tilt_jacobian * r.roll_pitch.covariance * r.tilt_jacobian->transpose();
        const int at[4] = {0, 1, 2, 5};
        for (int g = 0; g < 4; ++g)
          sd_alone[at[g]] = std::sqrt(std::max(0.0, r.extrinsics.covariance(at[g], at[g]) - share(g, g)));
      }
      const double scale[6] = {1e3, 1e3, 1e3, 1 / kDeg, 1 / kDeg, 1 / kDeg};
      std::printf("%-20s %-4s |", tex.c_str(), cfg.c_str());
      for (int i = 0; i < 6; ++i) std::printf(" %7.3f", r.extrinsics.estimated[i] ? err[i] * scale[i] : 0.0);
      std::printf(" |");
      for (int i = 0; i < 6; ++i) std::printf(" %6.3f", sd[i] * scale[i]);
      std::printf(" | %5.2f %5.2f %5.2f %5.2f %s%s%s\n", r.time.roll_pitch, r.time.tracking, r.time.decode, r.time.total,
                  calib::status_name(r.status), r.reason.empty() ? "" : ": ", r.reason.c_str());
      std::fflush(stdout);
      ++runs;
      if (!r.ok()) ++failed;
      for (int i = 0; i < 6; ++i)
        if (r.ok() && r.extrinsics.estimated[i]) {
          worst[i] = std::max(worst[i], std::abs(err[i]) * scale[i]);
          if (sd[i] > 0) {
            nees[i] += (err[i] / sd[i]) * (err[i] / sd[i]);
            nees_alone[i] += (err[i] / sd_alone[i]) * (err[i] / sd_alone[i]);
            ++counted[i];
          }
        }
      if (keep.empty()) std::filesystem::remove_all(dir);
    }
  std::printf("\n%d runs, %d not ok\n%-6s %12s %18s %34s\n", runs, failed, "param", "worst |err|", "RMS(err / sigma)",
              "RMS(err / sigma without the tilt's share)");
  for (int i = 0; i < 6; ++i)
    if (counted[i] > 0)
      std::printf("%-6s %9.4f %-3s %18.2f %34.2f\n", names[i], worst[i], i < 3 ? "mm" : "deg", std::sqrt(nees[i] / counted[i]),
                  std::sqrt(nees_alone[i] / counted[i]));
  return 0;
}

int windows(const bench::Args& args) {
  const std::string shared = PLANARVO_SHARED_DIR;
  const uint64_t seed = std::stoull(get(args, "seed", "1"));
  const bool nonholonomic = get(args, "method", "odometry") == "nonholonomic";
  sim::Options so;
  so.texture = shared + "/data/textures/" + get(args, "texture", "asphalt_01.png");
  so.extrinsics = config(get(args, "config", "1"), seed);
  so.seconds = std::stod(get(args, "seconds", "60"));
  so.seed = seed;
  so.odometry_noise = std::stod(get(args, "odometry_noise", "0.02"));
  const double window = std::stod(get(args, "window", "20")), step = std::stod(get(args, "step", "5"));
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("planarvo_bench_windows_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  ocl::Runtime rt;
  sim::simulate(rt, so, dir.string());
  io::Dataset ds(dir.string());
  const Extrinsics& t = so.extrinsics;
  const double truth[6] = {t.x, t.y, t.z, t.roll, t.pitch, t.yaw};
  const double scale[6] = {1e3, 1e3, 1e3, 1 / kDeg, 1 / kDeg, 1 / kDeg};
  const char* names[6] = {"x mm", "y mm", "z mm", "roll deg", "pitch deg", "yaw deg"};
  std::vector<std::array<double, 6>> values;
  std::vector<std::array<double, 6>> sigmas;
  int failed = 0;
  std::printf("%-8s %8s %8s %8s %8s %8s %8s %8s  %s\n", "start s", names[0], names[1], names[2], names[3], names[4],
              names[5], "time s", "status");
  const double fps = so.fps;
  for (double start = 0.0; start + window <= so.seconds + 1e-9; start += step) {
    calib::PipelineOptions po;
    if (nonholonomic) {
      po.graph.method = graph::CalibrationMethod::Nonholonomic;
      po.graph.fix_scale = true;
      po.graph.fixed_scale = t.z;
    }
    po.roll_pitch.max_frames = std::stoi(get(args, "frames", "10"));
    const auto t0 = std::chrono::steady_clock::now();
    calib::CameraCalibrator cal(rt, ds.camera(), po);
    const auto first = static_cast<int64_t>(std::llround(start * fps));
    const auto last = std::min<int64_t>(ds.frame_count(), first + static_cast<int64_t>(std::llround(window * fps)));
    for (int64_t i = first; i < last; ++i) {
      const cv::Mat f = ds.frame(i);
      cal.add_frame(f.data, f.cols, f.rows, f.step, ds.timestamp(i), ds.odometry_at(i),
                    i > first ? ds.direction_for_interval(i) : std::nullopt);
    }
    const calib::PipelineReport r = cal.finish();
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const Extrinsics& e = r.extrinsics.value;
    const std::array<double, 6> v = {e.x, e.y, e.z, e.roll, e.pitch, e.yaw};
    std::printf("%-8.1f", start);
    for (int k = 0; k < 6; ++k) std::printf(" %8.3f", v[static_cast<size_t>(k)] * scale[k]);
    std::printf(" %8.2f  %s%s%s\n", secs, calib::status_name(r.status), r.reason.empty() ? "" : ": ", r.reason.c_str());
    std::fflush(stdout);
    if (!r.ok()) {
      ++failed;
      continue;
    }
    values.push_back(v);
    std::array<double, 6> sd{};
    for (int k = 0; k < 6; ++k) sd[static_cast<size_t>(k)] = std::sqrt(std::max(0.0, r.extrinsics.covariance(k, k)));
    sigmas.push_back(sd);
  }
  std::filesystem::remove_all(dir);
  std::printf("\n%zu windows of %.0f s every %.0f s over %.0f s, %d not ok; roll and pitch from %s frames each\n",
              values.size(), window, step, so.seconds, failed, get(args, "frames", "10").c_str());
  std::printf("%-10s %12s %12s %12s %14s\n", "param", "truth", "mean", "std", "mean sigma");
  for (int k = 0; k < 6; ++k) {
    double mean = 0, var = 0, ms = 0;
    for (size_t i = 0; i < values.size(); ++i) {
      mean += values[i][static_cast<size_t>(k)];
      ms += sigmas[i][static_cast<size_t>(k)];
    }
    mean /= std::max<size_t>(1, values.size());
    ms /= std::max<size_t>(1, values.size());
    for (const auto& v : values) var += (v[static_cast<size_t>(k)] - mean) * (v[static_cast<size_t>(k)] - mean);
    var /= std::max<size_t>(1, values.size() - 1);
    std::printf("%-10s %12.3f %12.3f %12.3f %14.3f\n", names[k], truth[k] * scale[k], mean * scale[k],
                std::sqrt(var) * scale[k], ms * scale[k]);
  }
  return 0;
}
