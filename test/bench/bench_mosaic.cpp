// What the floor mosaic costs and how well it matches the ground: per variant (resolution, frame
// spacing, gain), the frames used, the image size, the time to decode frames, warp them on the
// device and blend them, the whole build (median of `rounds`; the first variant is also run once
// with a fresh, empty kernel cache: "cold"), the float tile memory held at most, and, for a
// simulated data set (simulation.yaml names its texture), the NCC of the written image against the
// texture where its YAML places it (test/common/mosaic_check.h; the trajectory is mapped to the
// world by the data set's first ground-truth pose). Through the C API, as `planarvo mosaic` uses it.
//
//   bench_mosaic DATASET TRAJECTORY.txt EXTRINSICS.yaml [rounds=3] [out=DIR] [variants=N (the first N)]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../common/mosaic_check.h"
#include "planarvo/planarvo.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void check(planarvo_status s, const char* what) {
  if (s != PLANARVO_OK) {
    std::fprintf(stderr, "bench_mosaic: %s: %s\n", what, planarvo_last_error());
    std::exit(1);
  }
}

struct Variant {
  const char* name;
  double resolution, spacing;
  int gain;
};

// The texture and texel size simulate wrote into simulation.yaml, if any.
bool simulation_texture(const fs::path& dir, std::string* texture, double* texel) {
  std::ifstream in(dir / "simulation.yaml");
  const std::string s = "\n" + std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  *texture = planarvo::test::yaml_value(s, "texture");
  const std::string t = planarvo::test::yaml_value(s, "texel_size");
  if (texture->empty() || t.empty()) return false;
  *texel = std::stod(t);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_mosaic DATASET TRAJECTORY.txt EXTRINSICS.yaml [rounds=3] [out=DIR]\n");
    return 2;
  }
  const std::string dir = argv[1], traj = argv[2];
  int rounds = 3;
  size_t nvariants = 100;
  fs::path out = fs::temp_directory_path() / "bench_mosaic";
  for (int i = 4; i < argc; ++i) {
    if (std::strncmp(argv[i], "rounds=", 7) == 0) rounds = std::max(1, std::atoi(argv[i] + 7));
    if (std::strncmp(argv[i], "out=", 4) == 0) out = argv[i] + 4;
    if (std::strncmp(argv[i], "variants=", 9) == 0) nvariants = std::max(1, std::atoi(argv[i] + 9));
  }
  fs::create_directories(out);
  planarvo_extrinsics e{};
  check(planarvo_extrinsics_load(argv[3], &e), "extrinsics");
  size_t n = 0;
  check(planarvo_read_tum(traj.c_str(), nullptr, nullptr, 0, &n), "trajectory");
  std::vector<double> t(n);
  std::vector<planarvo_se2> poses(n);
  check(planarvo_read_tum(traj.c_str(), t.data(), poses.data(), n, &n), "trajectory");
  planarvo_dataset* ds = nullptr;
  check(planarvo_dataset_open(dir.c_str(), nullptr, &ds), "data set");
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  check(planarvo_dataset_info_get(ds, &info), "info");
  for (double& v : t) v -= static_cast<double>(info.time_origin_ns) * 1e-9;
  planarvo_frame_data first{};
  check(planarvo_dataset_frame_data(ds, 0, &first), "frame data");
  std::string texture;
  double texel = 0;
  const bool simulated = first.has_groundtruth && simulation_texture(dir, &texture, &texel);

  const std::vector<Variant> variants = {{"1 mm, auto spacing", 0.001, 0, 1},
                                         {"1 mm, every frame", 0.001, -1, 1},
                                         {"1 mm, no gain", 0.001, 0, 0},
                                         {"0.5 mm, auto spacing", 0.0005, 0, 1},
                                         {"2 mm, auto spacing", 0.002, 0, 1}};
  std::printf("%s: %zu poses, %dx%d frames\n\n", dir.c_str(), n, info.camera.width, info.camera.height);
  std::printf("| variant | frames used | image px | decode s | warp s | blend s | build s | tile MB | NCC |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (size_t vi = 0; vi < std::min(nvariants, variants.size()); ++vi) {
    const Variant& v = variants[vi];
    std::vector<double> dec, warp, blend, total;
    planarvo_mosaic_info mi{};
    double ncc = 0;
    for (int r = (vi == 0 ? -1 : 0); r < rounds; ++r) {
      // Round -1: a fresh context on an empty kernel cache (the program is compiled).
      planarvo_context_options co;
      planarvo_context_options_init(&co);
      const fs::path cache = out / ("cache_" + std::to_string(r));
      if (r < 0) fs::remove_all(cache);
      const std::string cache_s = cache.string();
      co.cache_dir = cache_s.c_str();
      planarvo_context* ctx = nullptr;
      const Clock::time_point t0 = Clock::now();
      check(planarvo_context_create(&co, &ctx), "context");
      planarvo_mosaic_options o;
      planarvo_mosaic_options_init(&o);
      o.resolution = v.resolution;
      o.frame_spacing = v.spacing;
      o.estimate_gain = v.gain;
      planarvo_mosaic* m = nullptr;
      check(planarvo_mosaic_build(ctx, ds, &e, t.data(), poses.data(), n, &o, &m), "build");
      const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
      mi.struct_size = sizeof mi;
      check(planarvo_mosaic_info_get(m, &mi), "info");
      if (r < 0) {
        std::printf("| %s, cold kernel cache | %lld | %dx%d | %.2f | %.2f | %.2f | **%.2f** | %.1f | |\n", v.name,
                    static_cast<long long>(mi.frames_used), mi.width, mi.height, mi.seconds_decode, mi.seconds_warp,
                    mi.seconds_blend, seconds, static_cast<double>(mi.peak_tile_bytes) / 1e6);
      } else {
        dec.push_back(mi.seconds_decode);
        warp.push_back(mi.seconds_warp);
        blend.push_back(mi.seconds_blend);
        total.push_back(seconds);
      }
      if (r == 0 && simulated) {
        const fs::path png = out / ("mosaic_" + std::to_string(vi) + ".png");
        check(planarvo_mosaic_save(m, png.c_str()), "save");
        const planarvo::test::Ground ground(texture, texel, v.resolution);
        ncc = planarvo::test::ncc_against_ground(png, ground, first.groundtruth.x, first.groundtruth.y,
                                                 first.groundtruth.theta);
      }
      planarvo_mosaic_destroy(m);
      planarvo_context_destroy(ctx);
    }
    std::printf("| %s | %lld | %dx%d | %.2f | %.2f | %.2f | %.2f | %.1f | %s |\n", v.name,
                static_cast<long long>(mi.frames_used), mi.width, mi.height, median(dec), median(warp), median(blend),
                median(total), static_cast<double>(mi.peak_tile_bytes) / 1e6,
                simulated ? std::to_string(ncc).substr(0, 5).c_str() : "-");
  }
  planarvo_dataset_destroy(ds);
  return 0;
}
