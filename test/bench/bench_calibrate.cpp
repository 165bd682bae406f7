// The whole camera calibration (calib/pipeline.h: roll and pitch from images, tracking, the graph
// calibration) on simulated data sets written to disk and read back as a user's would be, against
// the simulator's true extrinsics. One row per run (errors and reported sigmas), then per
// parameter the worst error and the RMS of error / sigma over the runs.
//
//   bench_calibrate [key=value ...]
//     textures=a.png,b.png   (shared/data/textures)            default asphalt_01.png,anti_skid_tiles.png
//     configs=1,2,3,r1,r2    the paper's configurations; rN: random pose N   default 1,2,3,r1,r2
//     method=odometry|nonholonomic  (nonholonomic: the true height is given)  default odometry
//     seconds=S (20) size=WxH (640x480) odometry_noise=REL (0.02) noise=GREY (1) gain=REL (0.05)
//     seed=N (1) frames=N (roll/pitch frames; 0 = until the map is complete) keep=DIR (keep data sets)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "calib/pipeline.h"
#include "io/dataset.h"
#include "sim/simulator.h"
#include "ocl/runtime.h"

using namespace planarvo;

namespace {

constexpr double kDeg = M_PI / 180.0;

std::map<std::string, std::string> parse(int argc, char** argv) {
  std::map<std::string, std::string> m;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "bench_calibrate: arguments are key=value, not %s\n", a.c_str());
      std::exit(2);
    }
    m[a.substr(0, eq)] = a.substr(eq + 1);
  }
  return m;
}

std::string get(const std::map<std::string, std::string>& m, const std::string& k, const std::string& d) {
  const auto it = m.find(k);
  return it == m.end() ? d : it->second;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  return out;
}

Extrinsics config(const std::string& name, uint64_t seed) {
  if (name == "2") return {0.1917, -0.1078, 0.2164, 29.8 * kDeg, -4.6 * kDeg, 75.8 * kDeg};
  if (name == "3") return {0.2226, 0.0806, 0.1469, -26.6 * kDeg, 4.7 * kDeg, -18.6 * kDeg};
  if (name[0] == 'r') {
    sim::Random r(sim::derive_seed(seed, 500 + std::stoull(name.substr(1))));
    return {r.uniform(-0.3, 0.3), r.uniform(-0.2, 0.2), r.uniform(0.12, 0.3),
            r.uniform(-25, 25) * kDeg, r.uniform(-25, 25) * kDeg, r.uniform(-180, 180) * kDeg};
  }
  return {0.2441, -0.0185, 0.1787, 12.4 * kDeg, 17.6 * kDeg, -9.2 * kDeg};
}

}  // namespace

int main(int argc, char** argv) {
  const auto args = parse(argc, argv);
  const std::string shared = PLANARVO_SHARED_DIR;
  const auto textures = split(get(args, "textures", "asphalt_01.png,anti_skid_tiles.png"));
  const auto configs = split(get(args, "configs", "1,2,3,r1,r2"));
  const bool nonholonomic = get(args, "method", "odometry") == "nonholonomic";
  const std::string size = get(args, "size", "640x480");
  const std::string keep = get(args, "keep", "");
  const uint64_t seed = std::stoull(get(args, "seed", "1"));

  ocl::Runtime rt;
  std::printf("%-20s %-4s | %7s %7s %7s %7s %7s %7s | %6s %6s %6s %6s %6s %6s | %5s %5s %5s %5s %s\n", "texture", "cfg",
              "dx mm", "dy mm", "dz mm", "dr deg", "dp deg", "dyaw", "sx", "sy", "sz", "sr", "sp", "syaw", "rp s",
              "trk s", "dec s", "all s", "status");
  const char* names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  double worst[6] = {}, nees[6] = {};
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
      const calib::PipelineReport r = calib::calibrate_dataset(rt, ds, po);
      const Extrinsics& t = so.extrinsics;
      const Extrinsics& e = r.extrinsics.value;
      const double err[6] = {e.x - t.x, e.y - t.y, e.z - t.z, e.roll - t.roll, e.pitch - t.pitch,
                             std::remainder(e.yaw - t.yaw, 2 * M_PI)};
      double sd[6];
      for (int i = 0; i < 6; ++i) sd[i] = std::sqrt(std::max(0.0, r.extrinsics.covariance(i, i)));
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
            ++counted[i];
          }
        }
      if (keep.empty()) std::filesystem::remove_all(dir);
    }
  std::printf("\n%d runs, %d not ok\n%-6s %12s %18s\n", runs, failed, "param", "worst |err|", "RMS(err / sigma)");
  for (int i = 0; i < 6; ++i)
    if (counted[i] > 0)
      std::printf("%-6s %9.4f %-3s %18.2f\n", names[i], worst[i], i < 3 ? "mm" : "deg", std::sqrt(nees[i] / counted[i]));
  return 0;
}
