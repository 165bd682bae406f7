// Soak benchmark: tracks a long drive (100,000 frames by default, about an hour at 30 Hz) through
// the C API and prints, every block of frames, the process's resident memory and the time per
// frame, so that a leak or a slowdown shows; then tracks the same input again with a new tracker
// and says whether the trajectory is bit-identical. Prints tables, asserts nothing.
//
//   bench_soak [frames=100000] [size=640x480] [loop=40] [block=10000] [rerun=1]
//              [texture=asphalt_01.png] [seed=1]
//
// The frames cannot all be kept (100,000 at 640x480 is 30 GB), so one closed drive of `loop`
// seconds (a figure eight with speed changes, turning both ways, ending where and how it starts)
// is rendered once by the simulator into memory and fed again and again: the motion stays
// continuous across the seams and the ground truth of every interval is known. Rendering uses the
// engine's internals (sim::Renderer); the tracking goes through planarvo_tracker_* only.
#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "bench_args.h"
#include "core/se2.h"
#include "ocl/runtime.h"
#include "planarvo/planarvo.h"
#include "sim/simulator.h"

using namespace planarvo;

namespace {

constexpr double kFps = 30.0;

// Resident set size of this process (VmRSS), kB.
long rss_kb() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.compare(0, 6, "VmRSS:") == 0) return std::atol(line.c_str() + 6);
  return -1;
}

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The closed drive: a figure eight (lemniscate of Gerono, 2a by a metres; a = 1.5) traversed once in
// `seconds`, the curve parameter phi(t) = 2 pi s + 0.3 sin(4 pi s) (s = t / seconds) so that the
// speed changes by a factor of about 4 along the loop; the robot faces along the curve (a
// nonholonomic drive). phi(seconds) = 2 pi: the last frame's successor is the first frame.
struct Loop {
  std::vector<SE2> pose;  // true robot pose of each frame of the loop
  double length = 0, max_speed = 0, min_speed = 1e9, max_turn = 0;
};

Loop closed_drive(int frames, double a) {
  Loop loop;
  const double seconds = frames / kFps;
  auto point = [&](double t, double* x, double* y, double* dx, double* dy) {
    const double s = t / seconds;
    const double phi = 2 * M_PI * s + 0.3 * std::sin(4 * M_PI * s);
    const double dphi = (2 * M_PI + 0.3 * 4 * M_PI * std::cos(4 * M_PI * s)) / seconds;
    *x = a * std::sin(phi);
    *y = 0.5 * a * std::sin(2 * phi);
    *dx = a * std::cos(phi) * dphi;
    *dy = a * std::cos(2 * phi) * dphi;
  };
  for (int k = 0; k < frames; ++k) {
    double x, y, dx, dy;
    point(k / kFps, &x, &y, &dx, &dy);
    loop.pose.emplace_back(x, y, std::atan2(dy, dx));
    loop.max_speed = std::max(loop.max_speed, std::hypot(dx, dy));
    loop.min_speed = std::min(loop.min_speed, std::hypot(dx, dy));
  }
  for (int k = 0; k < frames; ++k) {
    const SE2 m = loop.pose[static_cast<size_t>(k)].inverse() * loop.pose[static_cast<size_t>((k + 1) % frames)];
    loop.length += std::hypot(m.x, m.y);
    loop.max_turn = std::max(loop.max_turn, std::abs(m.theta) * kFps);
  }
  return loop;
}

// The loop's 8-bit frames, one after another in one buffer: the simulator's renderer at each
// pose, then its camera model (gain and offset as slow sinusoids that are periodic over the loop,
// so the seam has no brightness jump either; 1 grey level of noise).
std::vector<uint8_t> render_loop(const Loop& loop, const sim::Options& so) {
  ocl::Runtime rt;
  std::printf("rendering on %s / %s\n", rt.device_info().platform_name.c_str(), rt.device_info().device_name.c_str());
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  const size_t n = loop.pose.size();
  const size_t bytes = static_cast<size_t>(so.camera.width) * static_cast<size_t>(so.camera.height);
  std::vector<uint8_t> frames(n * bytes);
  for (size_t k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / static_cast<double>(n);
    sim::Exposure e;
    e.gain = 1 + so.gain_variation * std::sin(2 * M_PI * 3 * s);
    e.offset = 60 * so.gain_variation * std::sin(2 * M_PI * 2 * s + 1.0);
    const cv::Mat img = sim::apply_camera(renderer.render_float(loop.pose[k]), e, so.pixel_noise,
                                          sim::derive_seed(so.seed, 1000 + k));
    for (int r = 0; r < img.rows; ++r)
      std::memcpy(frames.data() + k * bytes + static_cast<size_t>(r * img.cols), img.ptr(r),
                  static_cast<size_t>(img.cols));
  }
  return frames;
}

void check(planarvo_status s, const char* what) {
  if (s == PLANARVO_OK) return;
  std::fprintf(stderr, "bench_soak: %s: %s: %s\n", what, planarvo_status_name(s), planarvo_last_error());
  std::exit(1);
}

// The p-quantile of the first n values of v (reordered in place: no allocation).
double percentile(std::vector<double>* v, size_t n, double p) {
  if (n == 0) return 0;
  const size_t i = std::min(n - 1, static_cast<size_t>(p * static_cast<double>(n)));
  const auto begin = v->begin();
  std::nth_element(begin, begin + static_cast<std::ptrdiff_t>(i), begin + static_cast<std::ptrdiff_t>(n));
  return (*v)[i];
}

struct Input {
  const Loop* loop;
  const std::vector<uint8_t>* frames;
  planarvo_camera camera;
  planarvo_extrinsics extrinsics;
};

// One run: every frame's pose and motion, for the comparison.
struct Run {
  std::vector<planarvo_se2> pose, motion;
};

void print_header() {
  std::printf("%8s %9s %9s %8s %8s %8s %8s %7s %6s %6s %8s %9s %9s\n", "frames", "rss_MB", "d_rss_MB", "med_ms",
              "p99_ms", "max_ms", "eng_ms", "ok", "degr", "lost", "kf", "rms_mm", "drift_%");
}

Run track_all(planarvo_context* ctx, const Input& in, int64_t count, int64_t block) {
  planarvo_tracker* tracker = nullptr;
  check(planarvo_tracker_create(ctx, &in.camera, &in.extrinsics, nullptr, &tracker), "planarvo_tracker_create");
  Run run;
  // Everything this loop keeps is allocated before it starts: what the process grows by is the
  // library's.
  run.pose.resize(static_cast<size_t>(count));
  run.motion.resize(static_cast<size_t>(count));
  const size_t b = static_cast<size_t>(block);
  std::vector<double> wall(b), engine(b), dt(b);
  std::vector<planarvo_se2> truth(b), est(b);
  const size_t n = in.loop->pose.size();
  const size_t bytes = static_cast<size_t>(in.camera.width) * static_cast<size_t>(in.camera.height);
  long rss_ref = -1;
  int ok = 0, degraded = 0, lost = 0, keyframes = 0;
  size_t in_block = 0, intervals = 0;
  double max_ms = 0;
  print_header();
  for (int64_t k = 0; k < count; ++k) {
    const size_t f = static_cast<size_t>(k) % n;
    planarvo_image image{in.frames->data() + f * bytes, in.camera.width, in.camera.height,
                         static_cast<size_t>(in.camera.width), PLANARVO_GRAY8};
    planarvo_track_result r{};
    r.struct_size = sizeof r;
    const double t0 = now_ms();
    check(planarvo_tracker_track(tracker, &image, static_cast<double>(k) / kFps, &r), "planarvo_tracker_track");
    const double ms = now_ms() - t0;
    run.pose[static_cast<size_t>(k)] = r.pose;
    run.motion[static_cast<size_t>(k)] = r.motion;
    wall[in_block] = ms;
    engine[in_block] = r.ms;
    max_ms = std::max(max_ms, ms);
    ok += r.status == PLANARVO_TRACK_OK;
    degraded += r.status == PLANARVO_TRACK_DEGRADED;
    lost += r.status == PLANARVO_TRACK_LOST;
    keyframes += r.keyframe != 0;
    if (k > 0) {
      const SE2 m = in.loop->pose[(f + n - 1) % n].inverse() * in.loop->pose[f];
      truth[intervals] = {m.x, m.y, m.theta};
      est[intervals] = r.motion;
      dt[intervals] = 1 / kFps;
      ++intervals;
    }
    if (++in_block < b && k + 1 < count) continue;
    planarvo_motion_accuracy acc{};
    acc.struct_size = sizeof acc;
    check(planarvo_evaluate_motions(est.data(), truth.data(), dt.data(), nullptr, intervals, 1e-3, &acc),
          "planarvo_evaluate_motions");
    const long rss = rss_kb();
    if (rss_ref < 0) rss_ref = rss;  // the reference: after the first block (warm-up)
    const double median = percentile(&wall, in_block, 0.5), p99 = percentile(&wall, in_block, 0.99);
    std::printf("%8" PRId64 " %9.2f %+9.3f %8.2f %8.2f %8.1f %8.2f %7d %6d %6d %8d %9.4f %9.4f\n", k + 1, rss / 1024.0,
                (rss - rss_ref) / 1024.0, median, p99, max_ms, percentile(&engine, in_block, 0.5), ok, degraded, lost,
                keyframes, acc.rms_translation * 1e3, acc.endpoint_drift * 100);
    std::fflush(stdout);
    in_block = intervals = 0;
    ok = degraded = lost = keyframes = 0;
    max_ms = 0;
  }
  planarvo_tracker_destroy(tracker);
  return run;
}

// Bitwise comparison of two runs: the number of frames whose pose or motion differ in any bit,
// and the largest difference of any component.
void compare(const Run& a, const Run& b) {
  int64_t differing = 0, first = -1;
  double max_diff = 0;
  for (size_t k = 0; k < a.pose.size(); ++k) {
    const bool same = std::memcmp(&a.pose[k], &b.pose[k], sizeof(planarvo_se2)) == 0 &&
                      std::memcmp(&a.motion[k], &b.motion[k], sizeof(planarvo_se2)) == 0;
    if (same) continue;
    if (first < 0) first = static_cast<int64_t>(k);
    ++differing;
    const double d[6] = {a.pose[k].x - b.pose[k].x, a.pose[k].y - b.pose[k].y, a.pose[k].theta - b.pose[k].theta,
                         a.motion[k].x - b.motion[k].x, a.motion[k].y - b.motion[k].y,
                         a.motion[k].theta - b.motion[k].theta};
    for (double v : d) max_diff = std::max(max_diff, std::abs(v));
  }
  std::printf("rerun: %s: %" PRId64 " of %zu frames differ (pose or motion, bitwise), max difference %.3g",
              differing == 0 ? "bit-identical" : "NOT bit-identical", differing, a.pose.size(), max_diff);
  if (first >= 0) std::printf(", first at frame %" PRId64, first);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const bench::Args args = bench::parse_args(argc, argv, "bench_soak");
  const int64_t frames = std::atoll(bench::get(args, "frames", "100000").c_str());
  const int64_t block = std::atoll(bench::get(args, "block", "10000").c_str());
  const double loop_seconds = std::atof(bench::get(args, "loop", "40").c_str());
  const bool rerun = bench::get(args, "rerun", "1") != "0";
  int width = 0, height = 0;
  if (std::sscanf(bench::get(args, "size", "640x480").c_str(), "%dx%d", &width, &height) != 2 || width < 64 ||
      height < 48 || frames < 2 || block < 1 || !(loop_seconds >= 2)) {
    std::fprintf(stderr, "bench_soak: frames >= 2, block >= 1, size=WxH (at least 64x48), loop >= 2 seconds\n");
    return 2;
  }
  sim::Options so;
  so.texture = std::string(PLANARVO_SHARED_DIR) + "/data/textures/" + bench::get(args, "texture", "asphalt_01.png");
  so.camera = sim::default_camera(width, height);
  so.seed = static_cast<uint64_t>(std::atoll(bench::get(args, "seed", "1").c_str()));

  const Loop loop = closed_drive(static_cast<int>(std::lround(loop_seconds * kFps)), 1.5);
  std::printf("bench_soak: %" PRId64 " frames at %dx%d, %.0f Hz (%.1f min of driving); a closed figure-eight drive "
              "of %zu frames (%.1f m, speed %.2f..%.2f m/s, turn rate up to %.2f rad/s) over %s, fed %.1f times\n",
              frames, width, height, kFps, frames / kFps / 60, loop.pose.size(), loop.length, loop.min_speed,
              loop.max_speed, loop.max_turn, bench::get(args, "texture", "asphalt_01.png").c_str(),
              static_cast<double>(frames) / static_cast<double>(loop.pose.size()));
  const double r0 = now_ms();
  const std::vector<uint8_t> pixels = render_loop(loop, so);
  std::printf("rendered in %.1f s (%.0f MB of frames)\n", (now_ms() - r0) / 1e3, pixels.size() / 1048576.0);

  planarvo_context* ctx = nullptr;
  check(planarvo_context_create(nullptr, &ctx), "planarvo_context_create");
  planarvo_device_info info{};
  info.struct_size = sizeof info;
  check(planarvo_context_device(ctx, &info), "planarvo_context_device");
  check(planarvo_context_prepare_kernels(ctx), "planarvo_context_prepare_kernels");  // not in the first frame's time
  std::printf("tracking on %s / %s through the C API\n", info.platform_name, info.device_name);
  const CameraModel& c = so.camera;
  Input in{&loop, &pixels, {}, {}};
  in.camera = {c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3, {0, 0, 0, 0},
               c.rolling_shutter_readout, c.exposure_time};
  const Extrinsics& e = so.extrinsics;
  in.extrinsics = {e.x, e.y, e.z, e.roll, e.pitch, e.yaw};
  std::printf("per block of %" PRId64 " frames: rss = VmRSS, d_rss its change since frame %" PRId64
              "; med/p99/max = wall ms per planarvo_tracker_track; eng = the engine's own median ms; ok/degr/lost "
              "frames, kf keyframes; rms = per-frame translation error, drift = block endpoint error / distance\n",
              block, block);
  const double t0 = now_ms();
  std::printf("first run\n");
  const Run first = track_all(ctx, in, frames, block);
  std::printf("tracked in %.1f s\n", (now_ms() - t0) / 1e3);
  if (rerun) {
    const double t1 = now_ms();
    std::printf("second run: a new tracker on the same context, the same frames\n");
    const Run second = track_all(ctx, in, frames, block);
    std::printf("tracked in %.1f s\n", (now_ms() - t1) / 1e3);
    compare(first, second);
  }
  planarvo_context_destroy(ctx);
  return 0;
}
