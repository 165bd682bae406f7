// Benchmark and evaluation of the tracker. Prints tables, asserts nothing.
//   bench_track kernel   [width height]   the fused pass per work-group shape / pixels per
//                                          work-item / fast math, median ms per pass
//   bench_track kernel w h wx wy pix hist fast [rounds]   one configuration
//   bench_track accuracy [key=value...]     simulated sequences tracked against ground truth
//       (seconds, w, h, seed, levels, finest, refine_kf, conv, huber, overlap, maxit=l0,l1,..,
//        textures=a.png,b.png; see main())
#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <sys/resource.h>

#include <opencv2/imgcodecs.hpp>

#include "core/se2.h"
#include "image/undistort.h"
#include "io/simulator.h"
#include "ocl/runtime.h"
#include "track/tracker.h"
#include "track/warp_model.h"
#include "track/warp_reduce.h"
#include "../unit/track_test_pyramid.h"

using namespace planarvo;

namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Process CPU time (all threads: PoCL's workers too), ms: less sensitive than wall time to
// other processes competing for the two cores.
double cpu_ms() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return 1e3 * (u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-3 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

constexpr int kMaxLevelsBench = track::kMaxLevels;

std::string texture_path(const std::string& name) {
  return std::string(PLANARVO_SHARED_DIR) + "/data/textures/" + name;
}

struct KernelConfig { int wx, wy, pix, hist; bool fast; };

int bench_kernel(int width, int height, const std::vector<KernelConfig>& only, int reps) {
  ocl::Runtime rt;
  std::printf("device: %s / %s\n", rt.device_info().platform_name.c_str(), rt.device_info().device_name.c_str());
  sim::Options so;
  so.texture = texture_path("asphalt_01.png");
  so.camera = sim::default_camera(width, height);
  so.camera.k1 = so.camera.k2 = 0.0;
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  const SE2 motion(0.01, 0.002, 0.02);
  const Pyramid ref = test::test_upload(rt, test::test_pyramid(renderer.render_float(SE2()), nullptr, 1));
  const Pyramid live = test::test_upload(rt, test::test_pyramid(renderer.render_float(motion), nullptr, 1));
  const track::MotionHomography mh = track::motion_homography(so.camera.K(), so.extrinsics, motion);
  track::WarpInputs in;
  in.H = mh.H;
  for (int i = 0; i < 3; ++i) in.G[static_cast<size_t>(i)] = mh.G[static_cast<size_t>(i)];
  in.huber_k = 5.0;

  using Row = KernelConfig;
  std::vector<Row> rows = only;
  if (rows.empty()) {
  for (int fast = 1; fast >= 0; --fast)
    for (const auto& s : std::vector<std::array<int, 2>>{{16, 1}, {32, 1}, {64, 1}, {128, 1}, {16, 4}, {32, 2}})
      for (int pix : {1, 2, 4, 8}) rows.push_back({s[0], s[1], pix, 16, fast != 0});
  rows.push_back({64, 1, 4, 0, true});
  rows.push_back({64, 1, 8, 0, true});
  }
  std::printf("%dx%d, one fused pass (enqueue, kernel, read-back of the partials, host sum)\n", width, height);
  std::printf("%6s %4s %4s %5s %5s %9s %9s %9s\n", "wg_x", "wg_y", "pix", "hist", "fast", "median_ms", "min_ms", "cpu_ms");
  // Rounds over all configurations, so that load from other processes spreads over all of them.
  std::vector<std::vector<double>> times(rows.size());
  std::vector<double> valid(rows.size()), cpu(rows.size(), 0.0);
  for (int round = 0; round < reps; ++round)
  for (size_t ri = 0; ri < rows.size(); ++ri) {
    const Row& r = rows[ri];
    track::WarpReduceOptions o;
    o.wg_x = r.wx; o.wg_y = r.wy; o.pixels_per_item = r.pix; o.stats = r.hist > 0; o.hist_bins = r.hist; o.fast_math = r.fast;
    track::WarpReduce wr(rt, 3, o);
    track::ReduceSums s;
    wr.run(ref.levels[0].data, width, height, live.levels[0].data, width, height, in, &s);
    const double c0 = cpu_ms();
    for (int i = 0; i < 5; ++i) {
      const double t0 = now_ms();
      wr.run(ref.levels[0].data, width, height, live.levels[0].data, width, height, in, &s);
      times[ri].push_back(now_ms() - t0);
    }
    cpu[ri] += (cpu_ms() - c0) / 5.0 / reps;
    valid[ri] = s.valid;
  }
  for (size_t ri = 0; ri < rows.size(); ++ri) {
    const Row& r = rows[ri];
    std::printf("%6d %4d %4d %5d %5d %9.3f %9.3f %9.3f  (valid %.0f)\n", r.wx, r.wy, r.pix, r.hist, r.fast ? 1 : 0,
                median(times[ri]), *std::min_element(times[ri].begin(), times[ri].end()), cpu[ri], valid[ri]);
  }
  // Launch overhead: the same pass on a tiny level.
  {
    track::WarpReduce wr(rt, 3);
    track::ReduceSums s;
    std::vector<double> t;
    for (int i = 0; i < 50; ++i) {
      const double t0 = now_ms();
      wr.run(ref.levels[0].data, 16, 2, live.levels[0].data, width, height, in, &s);
      t.push_back(now_ms() - t0);
    }
    std::printf("launch + read-back overhead (16x2 reference): median %.3f ms\n", median(t));
  }
  return 0;
}

struct SequenceSpec {
  std::string texture;
  double seconds = 10.0;
  int width = 640, height = 480;
  uint64_t seed = 1;
};

struct SequenceReport {
  int frames = 0, ok = 0, degraded = 0, lost = 0, keyframes = 0;
  double slope_v = 0, slope_w = 0, rms_mm = 0, max_mm = 0, rms_deg = 0;
  int gross = 0;
  double distance = 0, drift_pct = 0, heading_drift_deg = 0;
  double ms_render = 0, ms_pyramid = 0, ms_track = 0;
  double passes[kMaxLevelsBench] = {};
  double level_ms[kMaxLevelsBench] = {};
  double cpu_track = 0;
};

SequenceReport run_sequence(ocl::Runtime& rt, const SequenceSpec& spec, const track::TrackerOptions& topt,
                            bool verbose) {
  sim::Options so;
  so.texture = texture_path(spec.texture);
  so.camera = sim::default_camera(spec.width, spec.height);
  so.seconds = spec.seconds;
  so.seed = spec.seed;
  const sim::Trajectory traj = sim::generate_trajectory(so);
  const std::vector<sim::Exposure> exposure = sim::exposure_series(so, traj.t);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  const UndistortMap map = compute_undistort_map(so.camera);
  track::Tracker tracker(rt, so.camera, so.extrinsics, topt);

  SequenceReport rep;
  double sxx_v = 0, sxy_v = 0, sxx_w = 0, sxy_w = 0, se2 = 0, sr2 = 0;
  int n = 0;
  SE2 est_pose;
  for (size_t k = 0; k < traj.t.size(); ++k) {
    double t0 = now_ms();
    const cv::Mat img = sim::apply_camera(renderer.render_float(traj.pose[k]), exposure[k], so.pixel_noise,
                                          sim::derive_seed(so.seed, 1000 + k));
    double t1 = now_ms();
    const Pyramid pyr = test::test_upload(rt, test::test_pyramid(img, &map, topt.levels));
    rt.queue().finish();
    double t2 = now_ms();
    const double c2 = cpu_ms();
    const track::FrameResult r = tracker.track(pyr, traj.t[k]);
    double t3 = now_ms();
    rep.cpu_track += cpu_ms() - c2;
    rep.ms_render += t1 - t0;
    rep.ms_pyramid += t2 - t1;
    rep.ms_track += t3 - t2;
    ++rep.frames;
    rep.keyframes += r.keyframe;
    for (int l = 0; l < kMaxLevelsBench; ++l) {
      rep.passes[l] += r.iterations[static_cast<size_t>(l)];
      rep.level_ms[l] += r.level_ms[static_cast<size_t>(l)];
    }
    if (r.status == track::FrameResult::Status::Ok) ++rep.ok;
    if (r.status == track::FrameResult::Status::Degraded) ++rep.degraded;
    if (r.status == track::FrameResult::Status::Lost) ++rep.lost;
    if (k == 0) continue;
    const SE2 truth = traj.pose[k - 1].inverse() * traj.pose[k];
    const double dt = traj.t[k] - traj.t[k - 1];
    est_pose = est_pose * r.motion;
    const double e = std::hypot(r.motion.x - truth.x, r.motion.y - truth.y);
    const double er = wrap_angle(r.motion.theta - truth.theta);
    se2 += e * e;
    sr2 += er * er;
    rep.max_mm = std::max(rep.max_mm, e * 1e3);
    rep.gross += e > 1e-3;
    rep.distance += std::hypot(truth.x, truth.y);
    sxx_v += truth.x * truth.x / (dt * dt);
    sxy_v += truth.x * r.motion.x / (dt * dt);
    sxx_w += truth.theta * truth.theta / (dt * dt);
    sxy_w += truth.theta * r.motion.theta / (dt * dt);
    ++n;
    if (verbose && (e > 1e-3 || r.status != track::FrameResult::Status::Ok))
      std::printf("  frame %zu: %s %s err %.3f mm, truth (%.4f %.4f %.4f) est (%.4f %.4f %.4f) overlap %.2f\n", k,
                  track::status_name(r.status), r.reason, e * 1e3, truth.x, truth.y, truth.theta, r.motion.x,
                  r.motion.y, r.motion.theta, r.overlap);
  }
  const SE2 true_end = traj.pose.front().inverse() * traj.pose.back();
  rep.slope_v = sxx_v > 0 ? sxy_v / sxx_v : 0;
  rep.slope_w = sxx_w > 0 ? sxy_w / sxx_w : 0;
  rep.rms_mm = n ? 1e3 * std::sqrt(se2 / n) : 0;
  rep.rms_deg = n ? std::sqrt(sr2 / n) * 180 / M_PI : 0;
  rep.drift_pct = rep.distance > 0 ? 100 * std::hypot(est_pose.x - true_end.x, est_pose.y - true_end.y) / rep.distance : 0;
  rep.heading_drift_deg = wrap_angle(est_pose.theta - true_end.theta) * 180 / M_PI;
  return rep;
}

int bench_accuracy(const std::vector<std::string>& textures, double seconds, int width, int height,
                   uint64_t seed, const track::TrackerOptions& topt, bool verbose) {
  ocl::Runtime rt;
  std::printf("device: %s\n", rt.device_info().device_name.c_str());
  std::printf("%dx%d, %.0f s at 30 Hz per texture, mixed motion up to 0.8 m/s and 1.5 rad/s, noise 1, gain +-5%%, "
              "configuration 1; levels %d..%d\n", width, height, seconds, topt.levels - 1, topt.finest_level);
  std::printf("%-20s %6s %4s %4s %4s %4s %8s %8s %8s %8s %8s %5s %7s %7s %8s %8s   %s\n", "texture", "frames", "ok",
              "deg", "lost", "kf", "slope_v", "slope_w", "rms_mm", "max_mm", "rms_deg", "gross", "drift%", "head_dg",
              "ms_pyr*", "ms_track", "passes/frame by level");
  for (const std::string& tex : textures) {
    SequenceSpec spec;
    spec.texture = tex;
    spec.seconds = seconds;
    spec.width = width;
    spec.height = height;
    spec.seed = seed;
    const SequenceReport r = run_sequence(rt, spec, topt, verbose);
    std::printf("%-20s %6d %4d %4d %4d %4d %8.5f %8.5f %8.4f %8.4f %8.5f %5d %7.3f %7.3f %8.2f %8.2f  ", tex.c_str(),
                r.frames, r.ok, r.degraded, r.lost, r.keyframes, r.slope_v, r.slope_w, r.rms_mm, r.max_mm, r.rms_deg,
                r.gross, r.drift_pct, r.heading_drift_deg, r.ms_pyramid / r.frames, r.ms_track / r.frames);
    for (int l = topt.levels - 1; l >= 0; --l) std::printf(" %.2f", r.passes[l] / r.frames);
    std::printf("\n%-20s cpu ms/frame in track %.2f; wall ms per level:", "", r.cpu_track / r.frames);
    for (int l = topt.levels - 1; l >= 0; --l) std::printf(" L%d %.2f", l, r.level_ms[l] / r.frames);
    std::printf("\n");
    std::fflush(stdout);
  }
  std::printf("* ms_pyr: the tests' host-side pyramid and upload (not the OpenCL image pipeline)\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "kernel";
  if (mode == "kernel") {
    const int w = argc > 3 ? std::atoi(argv[2]) : 640, h = argc > 3 ? std::atoi(argv[3]) : 480;
    std::vector<KernelConfig> only;
    if (argc > 8)
      only.push_back({std::atoi(argv[4]), std::atoi(argv[5]), std::atoi(argv[6]), std::atoi(argv[7]), std::atoi(argv[8]) != 0});
    return bench_kernel(w, h, only, argc > 9 ? std::atoi(argv[9]) : 6);
  }
  if (mode == "accuracy") {
    // bench_track accuracy [key=value ...]: seconds=10 w=640 h=480 levels=4 finest=0
    //   refine_kf=0 maxit=a,b,c,d (per level from 0) textures=a.png,b.png seed=1
    double seconds = 10.0;
    int w = 640, h = 480;
    uint64_t seed = 1;
    track::TrackerOptions topt;
    std::vector<std::string> tex = {"asphalt_01.png", "anti_skid_tiles.png", "brick_floor.png",
                                    "aerial_ground_rock.png"};
    for (int i = 2; i < argc; ++i) {
      const std::string a = argv[i];
      const size_t eq = a.find('=');
      const std::string k = a.substr(0, eq), v = eq == std::string::npos ? "" : a.substr(eq + 1);
      auto list = [&](const std::string& x) {
        std::vector<std::string> out;
        size_t p = 0;
        while (p <= x.size()) {
          const size_t c = x.find(',', p);
          out.push_back(x.substr(p, c == std::string::npos ? std::string::npos : c - p));
          if (c == std::string::npos) break;
          p = c + 1;
        }
        return out;
      };
      if (k == "seconds") seconds = std::atof(v.c_str());
      else if (k == "w") w = std::atoi(v.c_str());
      else if (k == "h") h = std::atoi(v.c_str());
      else if (k == "seed") seed = std::strtoull(v.c_str(), nullptr, 10);
      else if (k == "levels") topt.levels = std::atoi(v.c_str());
      else if (k == "finest") topt.finest_level = std::atoi(v.c_str());
      else if (k == "refine_kf") topt.refine_keyframes = std::atoi(v.c_str()) != 0;
      else if (k == "conv") topt.convergence_px = std::atof(v.c_str());
      else if (k == "huber") topt.huber_factor = std::atof(v.c_str());
      else if (k == "overlap") topt.keyframe_overlap = std::atof(v.c_str());
      else if (k == "maxit") {
        const auto it = list(v);
        for (size_t l = 0; l < it.size() && l < topt.max_iterations.size(); ++l) topt.max_iterations[l] = std::atoi(it[l].c_str());
      } else if (k == "textures") tex = list(v);
      else {
        std::fprintf(stderr, "unknown option %s\n", a.c_str());
        return 2;
      }
    }
    return bench_accuracy(tex, seconds, w, h, seed, topt, std::getenv("BENCH_VERBOSE") != nullptr);
  }
  std::fprintf(stderr, "usage: bench_track kernel [w h [wx wy pix hist fast [rounds]]] | accuracy [key=value...]\n");
  return 2;
}
