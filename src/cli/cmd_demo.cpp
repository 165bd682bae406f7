// `planarvo demo`: the main job on a built-in default, step by step.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "common.h"
#include "drive.h"

namespace planarvo::cli {
namespace {

constexpr double kDeg = M_PI / 180.0;
namespace fs = std::filesystem;

// While the simulator renders, a second context builds the kernels that steps 4 and 5 use, so that
// a first run compiles them beside the simulator instead of after it: it builds the programs and
// tracks two synthetic frames, so that the driver also compiles each kernel for its work-group
// size. Step 4's context finds them in the program cache or the driver's own (PoCL's). Nothing
// to do when kernels come from prebuilt binaries or neither cache is there. A failure here is
// left for step 4 to report. Measured on the 2-core machine, a first run: 15.9 s without it,
// 14.5 s with it.
class KernelWarmup {
 public:
  KernelWarmup(const Args& args, planarvo_context* context, const planarvo_camera& camera,
               const planarvo_extrinsics& extrinsics)
      : args_(args), camera_(camera), extrinsics_(extrinsics) {
    // Only where what it builds is found again: a program cache, or the driver's own.
    planarvo_device_info device{};
    device.struct_size = sizeof device;
    check(planarvo_context_device(context, &device));
    useful_ = !args.has("kernel-binaries") && (*planarvo_context_cache_dir(context) || device.driver_caches_kernels);
  }
  // Starts it, once, after the simulator's own kernel is built and has run (its first progress
  // report): started before, the simulator's build waited for the warm-up's (measured: the
  // simulation took 15 s instead of 5).
  void start() {
    if (started_ || !useful_) return;
    started_ = true;
    thread_ = std::thread([this] {
      const auto t0 = std::chrono::steady_clock::now();
      try {
        run(args_, camera_, extrinsics_);
      } catch (const std::exception&) {
      }
      seconds_ = seconds_since(t0);
    });
  }
  // A progress callback (planarvo_progress_fn) that starts the warm-up at the first report, then
  // reports to the Progress in `next`.
  static int progress(void* self, double fraction, const char* stage) {
    auto* w = static_cast<KernelWarmup*>(self);
    if (fraction > 0) w->start();
    return w->next ? Progress::callback(w->next, fraction, stage) : 0;
  }
  Progress* next = nullptr;
  ~KernelWarmup() { wait(); }
  KernelWarmup(const KernelWarmup&) = delete;
  KernelWarmup& operator=(const KernelWarmup&) = delete;
  // How long it ran (after wait()): over a second or so, it compiled (a first run).
  double seconds() const { return seconds_; }
  // Seconds spent waiting for it to finish.
  double wait() {
    const auto t0 = std::chrono::steady_clock::now();
    if (thread_.joinable()) thread_.join();
    return seconds_since(t0);
  }

 private:
  static void run(const Args& args, const planarvo_camera& camera, const planarvo_extrinsics& extrinsics) {
    ContextPtr ctx = make_context(args);
    // A textured frame (smoothed noise) and the same frame moved by a pixel.
    const int w = camera.width, h = camera.height;
    std::vector<uint8_t> noise(static_cast<size_t>(w) * static_cast<size_t>(h)), a(noise.size()), b(noise.size());
    std::mt19937 rng(1);
    for (uint8_t& v : noise) v = static_cast<uint8_t>(rng() & 0xff);
    const auto at = [&](int x, int y) { return noise[static_cast<size_t>(std::clamp(y, 0, h - 1) * w + std::clamp(x, 0, w - 1))]; };
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        int sa = 0, sb = 0;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            sa += at(x + dx, y + dy);
            sb += at(x + dx + 1, y + dy);
          }
        a[static_cast<size_t>(y * w + x)] = static_cast<uint8_t>(sa / 25);
        b[static_cast<size_t>(y * w + x)] = static_cast<uint8_t>(sb / 25);
      }
    planarvo_tracker_options to;
    planarvo_tracker_options_init(&to);
    planarvo_tracker* t = nullptr;
    check(planarvo_tracker_create(ctx.get(), &camera, &extrinsics, &to, &t));
    planarvo_track_result r{};
    r.struct_size = sizeof r;
    for (int k = 0; k < 2; ++k) {
      const planarvo_image image{k ? b.data() : a.data(), w, h, static_cast<size_t>(w), PLANARVO_GRAY8};
      planarvo_tracker_track(t, &image, k / 30.0, &r);
    }
    planarvo_tracker_destroy(t);
    check(planarvo_context_prepare_kernels_for(ctx.get(), "calibrate"));
  }

  const Args& args_;
  const planarvo_camera camera_;
  const planarvo_extrinsics extrinsics_;
  bool useful_ = false, started_ = false;
  double seconds_ = 0;
  std::thread thread_;
};

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
  KernelWarmup warmup(args, ctx.get(), o.camera, o.extrinsics);
  warmup.next = &progress;
  o.progress = &KernelWarmup::progress;
  o.progress_user_data = &warmup;
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
  const double waited = warmup.wait();
  if (warmup.seconds() > 2.0)
    std::printf("   (a first run: the OpenCL kernels of steps 4 and 5 were compiled during step 1, in %.1f s%s; they "
                "are cached now)\n",
                warmup.seconds(), waited > 0.5 ? (", " + std::to_string(static_cast<int>(waited + 0.5)) +
                                                  " s of it waited for here").c_str() : "");
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
