// Benchmark and evaluation of the tracker. Prints tables, asserts nothing.
//   bench_track kernel   [width height]   the fused pass per work-group shape / pixels per
//                                          work-item / lanes / fast math, median ms per pass
//   bench_track kernel w h wx wy pix hist fast lanes [rounds]   one configuration
//   bench_track speed [w h] [seconds] [rounds] [configs] [scenes] [paced]   ms per frame through the
//                                          camera-frame API (median, mean, and the p99 and maximum over
//                                          the median); paced=1 hands each frame at its time (the
//                                          camera's 30 fps) instead of as soon as the last returned
//   bench_track accuracy [key=value...]     simulated sequences tracked against ground truth
//       (seconds, w, h, seed, motion=mixed|straight|circle|spin, levels, finest, refine_kf, conv,
//        huber, overlap, maxit=l0,l1,.., textures=a.png,b.png or textures=all,
//        config=1|2|3 (the paper's camera configurations), perturb=1 (the tracker gets extrinsics
//        off by +10,-10,+10 mm and +2.5,-2.5,+2.5 deg), ext=x,y,z,roll,pitch,yaw (m, deg; instead
//        of config), fov=deg, motion=...|car, speed=m/s, turn=rad/s, radius=m (car), noise=grey
//        levels, select=B0,B1,.. (level l on one pixel per Bl x Bl block), prior=0|1 (a
//        subsampled level joined with the level before it), prior_chi2=X (its consistency test; 0: off),
//        prefilter=0|1 (level 0 smoothed before the pyramid; default 1), search=0 (no motion search for frames that would be Lost), the fused pass's lanes=1|8, pix=N,
//        wg=XxY; scene extras ss=N (the renderer's supersampling), mip=0|1, dist=0 (no lens distortion), readout=S, exposure=S (rolling shutter, motion blur; seconds), lamp=F, reflection=GREY, shadow=F (the camera's light; then a line of the learnt photometric model's error against it at 2 s and at the end), gain=A (the camera's gain drift), unroll=0 (the tracker not told the readout nor the exposure), told_readout=S, told_exposure=S (told another), rs_tol=PX, decorrelate=0 (the noise's share left in the gradients, image/gradient_noise.h), brightness=0 (no brightness model); BENCH_PREBLUR=sigma blurs each camera image first; BENCH_VERBOSE=1 adds per-level
//        times, the slowest frames and the frames not tracked ok; see main())
//   bench_track nees [key=value...]         NEES of the covariances (alignment and frame-to-frame
//       motion) and the lag-1 correlation of the errors per texture x configuration x size x
//       finest level (seconds=5, seed=1, textures=..|all, configs=1,2,3, sizes=640x480,320x240,
//       finest=0,1; noise=1 grey level; tracker: conv, huber, brightness=0|1, maxit=l0,l1,..,
//       step_fraction, rho);
//       BENCH_NEES_CSV=file also writes one row per frame tracked ok
// (OpenCV's findTransformECC against the tracker on the same pairs: bench_ecc.)
#include <algorithm>
#include <array>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "core/se2.h"
#include "image/photometric.h"
#include "image/undistort.h"
#include "ocl/runtime.h"
#include "sim/simulator.h"
#include "track/evaluation.h"
#include "track/tracker.h"
#include "track/warp_model.h"
#include "track/warp_reduce.h"
#include "../unit/track_test_pyramid.h"
#include "bench_ecc.h"
#include "bench_scene.h"

using namespace planarvo;
using bench::Scene;
using bench::all_textures;
using bench::describe;
using bench::split;
using bench::texture_path;

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

// The tail of per-frame times: the 99th percentile and the maximum, each over the median.
struct Tail {
  double median = 0, p99_over_median = 0, max_over_median = 0;
};
Tail tail(std::vector<double> ms) {
  Tail t;
  if (ms.empty()) return t;
  std::sort(ms.begin(), ms.end());
  t.median = ms[ms.size() / 2];
  const double p99 = ms[std::min(ms.size() - 1, static_cast<size_t>(0.99 * static_cast<double>(ms.size())))];
  if (t.median > 0) {
    t.p99_over_median = p99 / t.median;
    t.max_over_median = ms.back() / t.median;
  }
  return t;
}

constexpr int kMaxLevelsBench = track::kMaxLevels;

// A calibration error of fixed signs: +10, -10, +10 mm in x, y, z and +2.5, -2.5, +2.5 degrees
// in roll, pitch, yaw (the paper's Figure 7 perturbs by this much).
Extrinsics perturbed(Extrinsics e) {
  const double d = M_PI / 180.0;
  e.x += 0.010; e.y -= 0.010; e.z += 0.010;
  e.roll += 2.5 * d; e.pitch -= 2.5 * d; e.yaw += 2.5 * d;
  return e;
}

struct KernelConfig { int wx, wy, pix, hist; bool fast; int lanes; };

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
    for (const auto& s : std::vector<std::array<int, 2>>{{8, 1}, {16, 1}, {32, 1}, {64, 1}, {16, 4}, {32, 2}}) {
      for (int pix : {8, 16, 32}) rows.push_back({s[0], s[1], pix, 0, false, 8});
      for (int pix : {4, 8}) rows.push_back({s[0], s[1], pix, 0, false, 1});
    }
    rows.push_back({16, 1, 8, 16, false, 8});
    rows.push_back({16, 1, 8, 16, false, 1});
    rows.push_back({16, 1, 8, 0, true, 8});
  }
  std::printf("%dx%d, one fused pass (enqueue, kernel, read-back of the partials, host sum)\n", width, height);
  std::printf("%6s %4s %4s %5s %5s %5s %9s %9s %9s\n", "wg_x", "wg_y", "pix", "lanes", "hist", "fast", "median_ms", "min_ms", "cpu_ms");
  // Rounds over all configurations, so that load from other processes spreads over all of them.
  std::vector<std::vector<double>> times(rows.size());
  std::vector<double> valid(rows.size()), cpu(rows.size(), 0.0);
  for (int round = 0; round < reps; ++round)
  for (size_t ri = 0; ri < rows.size(); ++ri) {
    const Row& r = rows[ri];
    track::WarpReduceOptions o;
    o.wg_x = r.wx; o.wg_y = r.wy; o.pixels_per_item = r.pix; o.lanes = r.lanes; o.stats = r.hist > 0; o.hist_bins = r.hist; o.fast_math = r.fast;
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
    std::printf("%6d %4d %4d %5d %5d %5d %9.3f %9.3f %9.3f  (valid %.0f)\n", r.wx, r.wy, r.pix, r.lanes, r.hist, r.fast ? 1 : 0,
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

// The simulator's frames of a sequence: 8-bit camera images, times and true poses.
struct SequenceReport {
  int frames = 0, ok = 0, degraded = 0, lost = 0, keyframes = 0;
  track::MotionAccuracy acc;
  double ms_frame = 0, ms_pipeline = 0, cpu_frame = 0;
  std::vector<double> ms;  // per frame after the first (which builds the programs and the first keyframe)
  std::vector<std::array<double, 5>> slow;  // verbose: (ms, frame, keyframe, passes, pipeline ms) per frame
  // verbose: (error mm, frame, frames since the keyframe, speed m/s, error / reported position std) per frame
  std::vector<std::array<double, 5>> worst;
  double passes[kMaxLevelsBench] = {};
  double level_ms[kMaxLevelsBench] = {};
  double std_pos_median = 0, std_pos_max = 0, std_head_median = 0, nees = 0, aniso_max = 0;
  // The honest status: frames reported Ok whose motion is more than 1 mm off (missed), frames
  // reported Degraded or Lost whose motion is within 1 mm (false alarms).
  int missed = 0, false_alarms = 0;
  // The local plane (TrackerOptions::local_plane) against the simulator's body: the attitude's
  // errors (roll, pitch; RMS and largest over frames after the first, degrees), and RMS(error/sigma).
  double att_rms[2] = {0, 0}, att_max[2] = {0, 0}, att_nz[2] = {0, 0};
  int att_n = 0;
  // Its mounting watch: the changes found (time, found at, distance driven in between) and the
  // mounting as the drive ended against the truth's (sim::knocked_extrinsics).
  struct Change {
    double time, found, driven, roll, pitch, dz;
  };
  std::vector<Change> changes;
  Extrinsics final_mounting;
  // FrameResult::texture_residual: the largest over frames within 0.2 mm, the smallest over
  // frames more than 1 mm off (the honest-status check's margin).
  double tex_good_max = 0, tex_bad_min = HUGE_VAL;
  // Under the camera's light: the photometric model against the light that made the images, at
  // 2 s of driving and at the end (flat_field_error); NaN while the model is the identity.
  struct FlatFieldError {
    double rms = NAN, p99 = NAN, with_value = NAN;
  } flat_2s, flat_end;
};

// The photometric model in use against the simulator's light: the model's gain per camera pixel
// (flat_field_to_distorted: 0 where it has no value) against the light's mean level there,
// gain * (the texture's mean) + add, both scaled to agree in the median. Relative errors over the
// pixels with a value that the light leaves below the white level (250); with_value: their
// fraction of the camera's pixels the light leaves below it (the corners the undistortion has no
// source for have none: 12.5 % at 640 x 480 with the default lens).
SequenceReport::FlatFieldError flat_field_error(const track::Tracker& tracker, const CameraModel& camera,
                                                const sim::Lighting& lighting, double floor_mean) {
  SequenceReport::FlatFieldError out;
  const PhotometricFit* fit = tracker.photometric_model();
  if (!fit || lighting.empty()) return out;
  const cv::Mat model = flat_field_to_distorted(*fit, camera);
  std::vector<double> ratio, err;
  long below_white = 0;
  for (int y = 0; y < model.rows; ++y)
    for (int x = 0; x < model.cols; ++x) {
      const double level = lighting.gain.at<float>(y, x) * floor_mean + lighting.add.at<float>(y, x);
      if (!(level < 250.0)) continue;
      ++below_white;
      if (model.at<float>(y, x) > 0.0f) ratio.push_back(level / model.at<float>(y, x));
    }
  if (ratio.empty()) return out;
  std::vector<double> sorted = ratio;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  const double k = sorted[sorted.size() / 2];
  double ss = 0.0;
  for (const double r : ratio) {
    err.push_back(std::abs(k / r - 1.0));
    ss += err.back() * err.back();
  }
  const size_t i99 = static_cast<size_t>(0.99 * static_cast<double>(err.size() - 1));
  std::nth_element(err.begin(), err.begin() + static_cast<long>(i99), err.end());
  out.rms = std::sqrt(ss / static_cast<double>(err.size()));
  out.p99 = err[i99];
  out.with_value = static_cast<double>(ratio.size()) / static_cast<double>(below_white);
  return out;
}

// unroll=0: the tracker is not told the camera's rolling shutter nor its exposure (what it did
// before it could take them out); told_readout=S, told_exposure=S: it is told S seconds (a wrong
// readout or exposure; told_exposure=0: the readout only).
bool g_tracker_knows_readout = true;
double g_told_readout = -1.0, g_told_exposure = -1.0;

// Renders and tracks a sequence frame by frame through the camera-frame API.
// tracker_extrinsics: what the tracker is told (so.extrinsics, the truth, when null).
SequenceReport run_sequence(ocl::Runtime& rt, const sim::Options& so, const track::TrackerOptions& topt,
                            bool verbose, const Extrinsics* tracker_extrinsics = nullptr) {
  const sim::Trajectory traj = sim::generate_trajectory(so);
  const std::vector<sim::Exposure> exposure = sim::exposure_series(so, traj.t);
  sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
  const sim::Lighting lighting = sim::camera_lighting(so);
  CameraModel tracker_camera = so.camera;
  if (!g_tracker_knows_readout) tracker_camera.rolling_shutter_readout = tracker_camera.exposure_time = 0.0;
  if (g_told_readout >= 0.0) tracker_camera.rolling_shutter_readout = g_told_readout;
  if (g_told_exposure >= 0.0) tracker_camera.exposure_time = g_told_exposure;
  track::Tracker tracker(rt, tracker_camera, tracker_extrinsics ? *tracker_extrinsics : so.extrinsics, topt);
  SequenceReport rep;
  std::vector<SE2> est, truth;
  std::vector<double> dts, std_pos, std_head;
  double nees = 0;
  int nees_n = 0, since_kf = 0;
  for (size_t k = 0; k < traj.t.size(); ++k) {
    cv::Mat img = bench::camera_frame(renderer, so, traj, exposure, k, lighting);
    // BENCH_PREBLUR=sigma: the camera image Gaussian-blurred before tracking (the interpolation
    // noise bias experiment, src/track/README.md).
    if (const char* pb = std::getenv("BENCH_PREBLUR"); pb && std::atof(pb) > 0.0)
      cv::GaussianBlur(img, img, cv::Size(0, 0), std::atof(pb));
    const double c0 = cpu_ms();
    // The simulator's wheel odometry (1 % noise per wheel and frame): the mounting watch's height.
    if (topt.local_plane) tracker.set_odometry(traj.odometry[k]);
    const track::FrameResult r = tracker.track(img.data, img.cols, img.rows, img.step, traj.t[k]);
    rep.cpu_frame += cpu_ms() - c0;
    if (!lighting.empty()) {
      const bool at_2s = k > 0 && traj.t[k] - traj.t[0] >= 2.0 && traj.t[k - 1] - traj.t[0] < 2.0;
      if (at_2s) rep.flat_2s = flat_field_error(tracker, tracker_camera, lighting, renderer.pyramid().mean);
      if (k + 1 == traj.t.size()) rep.flat_end = flat_field_error(tracker, tracker_camera, lighting, renderer.pyramid().mean);
    }
    rep.ms_frame += r.ms;
    if (k > 0) rep.ms.push_back(r.ms);
    if (verbose && k > 0) {
      int np = 0;
      for (int l = 0; l < kMaxLevelsBench; ++l) np += r.iterations[static_cast<size_t>(l)];
      rep.slow.push_back({r.ms, static_cast<double>(k), static_cast<double>(r.keyframe), static_cast<double>(np),
                          r.pipeline_ms});
    }
    rep.ms_pipeline += r.pipeline_ms;
    ++rep.frames;
    rep.keyframes += r.keyframe;
    for (int l = 0; l < kMaxLevelsBench; ++l) {
      rep.passes[l] += r.iterations[static_cast<size_t>(l)];
      rep.level_ms[l] += r.level_ms[static_cast<size_t>(l)];
    }
    rep.ok += r.status == track::FrameResult::Status::Ok;
    rep.degraded += r.status == track::FrameResult::Status::Degraded;
    rep.lost += r.status == track::FrameResult::Status::Lost;
    if (k == 0) continue;
    if (topt.local_plane) {
      rep.final_mounting = r.mounting_changed ? r.changed_mounting : r.mounting;
      if (r.mounting_changed) {
        size_t from = k;
        while (from > 0 && traj.t[from] > r.mounting_change.time + 1e-9) --from;
        rep.changes.push_back({r.mounting_change.time, traj.t[k], traj.distance[k] - traj.distance[from],
                               r.mounting_change.step.roll, r.mounting_change.step.pitch, r.mounting_change.dz});
      }
      const BodyAttitude a = sim::body_attitude(so, traj, traj.t[k]);
      const double err[2] = {r.attitude.roll - a.roll, r.attitude.pitch - a.pitch};
      for (int i = 0; i < 2; ++i) {
        rep.att_rms[i] += err[i] * err[i];
        rep.att_max[i] = std::max(rep.att_max[i], std::abs(err[i]));
        const double var = r.attitude_covariance(i, i);
        if (var > 0) rep.att_nz[i] += err[i] * err[i] / var;
      }
      ++rep.att_n;
      if (verbose && (std::abs(err[0]) > 0.2 * M_PI / 180 || std::abs(err[1]) > 0.2 * M_PI / 180))
        std::printf("  frame %zu: attitude roll %.3f (true %.3f) pitch %.3f (true %.3f) deg, sigma %.3f %.3f\n", k,
                    r.attitude.roll * 180 / M_PI, a.roll * 180 / M_PI, r.attitude.pitch * 180 / M_PI,
                    a.pitch * 180 / M_PI, std::sqrt(r.attitude_covariance(0, 0)) * 180 / M_PI,
                    std::sqrt(r.attitude_covariance(1, 1)) * 180 / M_PI);
    }
    const SE2 t = traj.pose[k - 1].inverse() * traj.pose[k];
    est.push_back(r.motion.value);
    truth.push_back(t);
    dts.push_back(traj.t[k] - traj.t[k - 1]);
    const double e = std::hypot(r.motion.value.x - t.x, r.motion.value.y - t.y);
    rep.missed += r.status == track::FrameResult::Status::Ok && e > 1e-3;
    if (e <= 2e-4 && std::isfinite(r.texture_residual))
      rep.tex_good_max = std::max(rep.tex_good_max, r.texture_residual);
    if (e > 1e-3 && r.texture_residual > 0) rep.tex_bad_min = std::min(rep.tex_bad_min, r.texture_residual);
    rep.false_alarms += r.status != track::FrameResult::Status::Ok && e <= 1e-3;
    since_kf = r.keyframe ? 0 : since_kf + 1;
    if (verbose)
      rep.worst.push_back({e * 1e3, static_cast<double>(k), static_cast<double>(since_kf),
                           std::hypot(t.x, t.y) / (traj.t[k] - traj.t[k - 1]),
                           e / std::sqrt(std::max(1e-30, std::max(r.motion.covariance(0, 0), r.motion.covariance(1, 1))))});
    if (r.status == track::FrameResult::Status::Ok) {
      std_pos.push_back(std::sqrt(std::max(r.motion.covariance(0, 0), r.motion.covariance(1, 1))));
      std_head.push_back(std::sqrt(r.motion.covariance(2, 2)));
      const Eigen::Vector2d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(r.motion.covariance.topLeftCorner<2, 2>()).eigenvalues();
      rep.aniso_max = std::max(rep.aniso_max, std::sqrt(ev(1) / ev(0)));
      // Normalised error of the motion with its covariance (`bench_track nees` has more).
      const Eigen::Vector3d xi = (r.motion.value.inverse() * t).log();
      nees += xi.dot(r.motion.covariance.ldlt().solve(xi));
      ++nees_n;
    }
    if (verbose && (e > 1e-3 || r.status != track::FrameResult::Status::Ok))
      std::printf("  frame %zu: %s %s err %.3f mm, truth (%.4f %.4f %.4f) est (%.4f %.4f %.4f) overlap %.2f texture "
                  "residual %.3f\n", k, track::status_name(r.status), r.reason, e * 1e3, t.x, t.y, t.theta,
                  r.motion.value.x, r.motion.value.y, r.motion.value.theta, r.overlap, r.texture_residual);
  }
  rep.acc = track::evaluate_motions(est, truth, dts);
  rep.std_pos_median = median(std_pos);
  rep.std_pos_max = std_pos.empty() ? 0 : *std::max_element(std_pos.begin(), std_pos.end());
  rep.std_head_median = median(std_head);
  rep.nees = nees_n ? nees / nees_n : 0;
  return rep;
}

// The six rows with the largest first column, each value with its column's decimals.
void print_largest(const char* title, std::vector<std::array<double, 5>> rows, const std::array<int, 5>& decimals) {
  const size_t n = std::min<size_t>(6, rows.size());
  std::partial_sort(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(n), rows.end(),
                    [](const auto& a, const auto& b) { return a[0] > b[0]; });
  std::printf("  %s:", title);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < 5; ++j) std::printf("%s%.*f%s", j ? " " : " (", decimals[j], rows[i][j], j == 4 ? ")" : "");
  std::printf("\n");
}

int bench_accuracy(const std::vector<std::string>& textures, double seconds, int width, int height,
                   uint64_t seed, const Scene& scene, bool perturb, const track::TrackerOptions& topt, bool verbose) {
  ocl::Runtime rt;
  std::printf("device: %s\n", rt.device_info().device_name.c_str());
  const Extrinsics truth = scene.extrinsics();
  const Extrinsics told = perturb ? perturbed(truth) : truth;
  const int config = scene.has_ext ? 0 : scene.config;
  std::printf("%dx%d, %.0f s at 30 Hz per texture (seed %llu), %s, gain/offset drift 5%%, lens distortion; tracker "
              "levels %d, finest %d (-1: auto)\n",
              width, height, seconds, static_cast<unsigned long long>(seed), scene.summary().c_str(), topt.levels,
              topt.finest_level);
  std::printf("configuration %d (0: ext=): true extrinsics %s; tracker given %s%s\n", config, describe(truth).c_str(),
              describe(told).c_str(), perturb ? " (perturbed +10,-10,+10 mm, +2.5,-2.5,+2.5 deg)" : " (true)");
  std::printf("%-22s %4s %6s %4s %4s %4s %4s %4s %4s %8s %8s %7s %7s %8s %5s %7s %7s %7s %7s %6s %6s %6s  %s\n", "texture", "cfg",
              "frames", "ok", "deg", "lost", "kf", "miss", "f.a.", "slope_v", "slope_w", "rms_mm", "max_mm", "rms_deg", "gross",
              "drift%", "ms/fr", "ms_pipe", "cpu/fr", "med_ms", "p99/md", "max/md", "passes per frame, coarse to fine");
  for (const std::string& tex : textures) {
    const sim::Options so = scene.options(tex, seconds, width, height, seed);
    const SequenceReport r = run_sequence(rt, so, topt, verbose, &told);
    const double n = r.frames;
    std::printf("%-22s %3d%s %6d %4d %4d %4d %4d %4d %4d %8.5f %8.5f %7.4f %7.4f %8.5f %5d %7.3f %7.2f %7.2f %7.2f ",
                tex.c_str(), config, perturb ? "p" : " ", r.frames, r.ok, r.degraded, r.lost, r.keyframes, r.missed,
                r.false_alarms, r.acc.slope_linear, r.acc.slope_angular,
                r.acc.rms_translation * 1e3, r.acc.max_translation * 1e3, r.acc.rms_rotation * 180 / M_PI,
                r.acc.gross_errors, r.acc.endpoint_drift * 100, r.ms_frame / n, r.ms_pipeline / n, r.cpu_frame / n);
    const Tail t = tail(r.ms);
    std::printf("%6.2f %6.2f %6.2f ", t.median, t.p99_over_median, t.max_over_median);
    for (int l = topt.levels - 1; l >= 0; --l) std::printf(" %.2f", r.passes[l] / n);
    std::printf("\n");
    if (topt.local_plane && r.att_n > 0)
      std::printf("  local plane: roll error RMS %.3f max %.3f deg, pitch error RMS %.3f max %.3f deg; RMS error/sigma "
                  "%.2f, %.2f\n",
                  std::sqrt(r.att_rms[0] / r.att_n) * 180 / M_PI, r.att_max[0] * 180 / M_PI,
                  std::sqrt(r.att_rms[1] / r.att_n) * 180 / M_PI, r.att_max[1] * 180 / M_PI,
                  std::sqrt(r.att_nz[0] / r.att_n), std::sqrt(r.att_nz[1] / r.att_n));
    if (topt.local_plane && topt.on_mounting_change != track::TrackerOptions::MountingResponse::Ignore) {
      // The truth: the knocked mounting when the drive has a knock, else the one given.
      const Extrinsics knocked = sim::knocked_extrinsics(so);
      const Extrinsics& m = r.final_mounting;
      std::printf("  mounting: %zu change(s)", r.changes.size());
      for (const auto& c : r.changes)
        std::printf("; from %.3f s found at %.3f s (%.3f s, %.2f m later): roll %+.3f pitch %+.3f deg z %+.2f mm", c.time,
                    c.found, c.found - so.knock_time, c.driven, c.roll * 180 / M_PI, c.pitch * 180 / M_PI, c.dz * 1e3);
      std::printf("; as the drive ended off by roll %.3f pitch %.3f yaw %.3f deg, z %.2f mm\n",
                  (m.roll - knocked.roll) * 180 / M_PI, (m.pitch - knocked.pitch) * 180 / M_PI,
                  std::remainder(m.yaw - knocked.yaw, 2 * M_PI) * 180 / M_PI, (m.z - knocked.z) * 1e3);
    }
    std::printf("  texture residual (the honest-status check): largest of frames within 0.2 mm %.3f, smallest of "
                "frames over 1 mm %.3f\n", r.tex_good_max, r.tex_bad_min);
    if (!std::isnan(r.flat_end.with_value) || !std::isnan(r.flat_2s.with_value))
      std::printf("  flat field (the photometric model against the light, relative): at 2 s RMS %.2f %%, p99 %.2f %% "
                  "(%.1f %% of the camera's pixels below white have one); at the end RMS %.2f %%, p99 %.2f %% (%.1f %%)\n",
                  100 * r.flat_2s.rms, 100 * r.flat_2s.p99, 100 * r.flat_2s.with_value, 100 * r.flat_end.rms,
                  100 * r.flat_end.p99, 100 * r.flat_end.with_value);
    if (verbose)
      std::printf("  covariance: position std median %.2g m (max %.2g), heading std median %.2g rad; "
                  "mean NEES %.1f (3 if calibrated); largest std ratio of the position axes %.1f\n", r.std_pos_median,
                  r.std_pos_max, r.std_head_median, r.nees, r.aniso_max);
    if (verbose) {
      print_largest("slowest frames (ms, frame, keyframe, passes, pipeline ms)", r.slow, {2, 0, 0, 0, 2});
      print_largest("largest errors (mm, frame, frames since the keyframe, speed m/s, error / std)", r.worst,
                    {3, 0, 0, 2, 1});
      std::printf("  mean ms per level, coarse to fine:");
      for (int l = topt.levels - 1; l >= 0; --l) std::printf(" %.2f", r.level_ms[l] / n);
      std::printf("\n");
    }
    std::fflush(stdout);
  }
  return 0;
}

// NEES of the tracker's covariances against the simulator's truth. Per frame tracked `ok`:
// the alignment (the live pose in the keyframe's robot frame, T_kf^-1 T_k, reconstructed from
// the reported motions since the last keyframe; FrameResult::alignment_covariance) and the
// reported frame-to-frame motion (FrameResult::covariance); the error is the right
// perturbation xi = log(estimate^-1 truth), NEES = xi^T C^-1 xi (3 on average when C is right).
// Lag-1 correlation: of consecutive frames' errors, each component normalised by its standard
// deviation, averaged over x, y, theta (motion: all consecutive pairs; alignment: consecutive
// frames against the same keyframe).
struct NeesStats {
  std::vector<double> align, motion, motion_kf;  // motion_kf: frames whose previous frame is the keyframe
  std::vector<Eigen::Vector3d> zm_prev, zm_cur, za_prev, za_cur;
  int frames = 0, ok = 0, keyframes = 0;

  static double mean(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
  }
  static double corr(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
    if (a.size() < 3) return 0.0;
    double c = 0;
    for (int i = 0; i < 3; ++i) {
      double sab = 0, saa = 0, sbb = 0, ma = 0, mb = 0;
      for (size_t k = 0; k < a.size(); ++k) { ma += a[k](i); mb += b[k](i); }
      ma /= static_cast<double>(a.size());
      mb /= static_cast<double>(a.size());
      for (size_t k = 0; k < a.size(); ++k) {
        sab += (a[k](i) - ma) * (b[k](i) - mb);
        saa += (a[k](i) - ma) * (a[k](i) - ma);
        sbb += (b[k](i) - mb) * (b[k](i) - mb);
      }
      c += sab / std::sqrt(saa * sbb) / 3.0;
    }
    return c;
  }
};

double nees(const Eigen::Vector3d& xi, const Eigen::Matrix3d& C) { return xi.dot(C.ldlt().solve(xi)); }

Eigen::Vector3d normalised(const Eigen::Vector3d& xi, const Eigen::Matrix3d& C) {
  return {xi(0) / std::sqrt(C(0, 0)), xi(1) / std::sqrt(C(1, 1)), xi(2) / std::sqrt(C(2, 2))};
}

// One tracker's bookkeeping over a sequence.
struct NeesRun {
  track::Tracker tracker;
  NeesStats st;
  SE2 kf_truth, est_rel;  // the keyframe's true pose; the previous frame's estimate relative to it
  bool prev_ok = false, prev_kf = true;
  Eigen::Vector3d prev_zm, prev_za;

  int since_kf = 0;
  FILE* csv = nullptr;  // per-frame rows (BENCH_NEES_CSV)
  std::string tag;

  NeesRun(ocl::Runtime& rt, const sim::Options& so, const track::TrackerOptions& o) : tracker(rt, so.camera, so.extrinsics, o) {}

  void frame(const cv::Mat& img, double t, const SE2& truth_prev, const SE2& truth) {
    const track::FrameResult r = tracker.track(img.data, img.cols, img.rows, img.step, t);
    ++st.frames;
    if (r.status == track::FrameResult::Status::First) {
      kf_truth = truth;
      est_rel = SE2();
      prev_ok = false;
      prev_kf = true;
      since_kf = 0;
      ++st.keyframes;
      return;
    }
    const SE2 est_align = est_rel * r.motion.value;
    const bool ok = r.status == track::FrameResult::Status::Ok;
    if (ok) {
      ++st.ok;
      const Eigen::Vector3d xa = (est_align.inverse() * (kf_truth.inverse() * truth)).log();
      const Eigen::Vector3d xm = (r.motion.value.inverse() * (truth_prev.inverse() * truth)).log();
      st.align.push_back(nees(xa, r.alignment_covariance));
      st.motion.push_back(nees(xm, r.motion.covariance));
      if (csv) {
        const Eigen::Matrix3d& A = r.alignment_covariance;
        const Eigen::Matrix3d& M = r.motion.covariance;
        std::fprintf(csv, "%s,%d,%d,%.4f,%.4f,%d", tag.c_str(), st.frames - 1, since_kf + 1, r.overlap, r.sigma,
                     r.iterations[static_cast<size_t>(std::max(0, tracker.options().finest_level))]);
        for (int i = 0; i < 3; ++i) std::fprintf(csv, ",%.6e", xa(i));
        for (int i = 0; i < 3; ++i)
          for (int j = i; j < 3; ++j) std::fprintf(csv, ",%.6e", A(i, j));
        for (int i = 0; i < 3; ++i) std::fprintf(csv, ",%.6e", xm(i));
        for (int i = 0; i < 3; ++i)
          for (int j = i; j < 3; ++j) std::fprintf(csv, ",%.6e", M(i, j));
        const SE2 m = r.motion.value;
        std::fprintf(csv, ",%.6e,%.6e,%.6e,%d\n", m.x, m.y, m.theta, r.keyframe ? 1 : 0);
      }
      if (prev_kf) st.motion_kf.push_back(st.motion.back());
      const Eigen::Vector3d za = normalised(xa, r.alignment_covariance), zm = normalised(xm, r.motion.covariance);
      if (prev_ok) {
        st.zm_prev.push_back(prev_zm);
        st.zm_cur.push_back(zm);
        if (!prev_kf) {
          st.za_prev.push_back(prev_za);
          st.za_cur.push_back(za);
        }
      }
      prev_za = za;
      prev_zm = zm;
    }
    prev_ok = ok;
    if (r.keyframe) {
      ++st.keyframes;
      kf_truth = truth;
      est_rel = SE2();
      prev_kf = true;
      since_kf = 0;
    } else {
      est_rel = est_align;
      prev_kf = false;
      ++since_kf;
    }
  }
};

int bench_nees(const std::vector<std::string>& textures, const std::vector<int>& configs,
               const std::vector<std::array<int, 2>>& sizes, const std::vector<int>& finests, double seconds,
               uint64_t seed, double noise, const track::TrackerOptions& base) {
  ocl::Runtime rt;
  std::printf("device: %s\n", rt.device_info().device_name.c_str());
  std::printf("%.0f s at 30 Hz per sequence (seed %llu), mixed motion up to 0.8 m/s and 1.5 rad/s, noise %g grey "
              "level, gain drift 5%%, lens distortion, camera-frame API; tracker: convergence %g px\n", seconds,
              static_cast<unsigned long long>(seed), noise, base.convergence_px);
  std::printf("NEES: mean over the frames tracked ok of xi^T C^-1 xi (3 when C is right); align: the pose in the "
              "keyframe's frame; motion: the reported frame-to-frame motion (motion|kf: those right after a "
              "keyframe); lag1: correlation of consecutive errors, per component, mean of x, y, theta\n");
  std::printf("%-22s %3s %9s %6s %6s %4s %4s %8s %8s %9s %9s %9s\n", "texture", "cfg", "size", "finest", "frames",
              "ok", "kf", "nees_al", "nees_mo", "nees_mokf", "lag1_mo", "lag1_al");
  FILE* csv = std::getenv("BENCH_NEES_CSV") ? std::fopen(std::getenv("BENCH_NEES_CSV"), "w") : nullptr;
  if (csv)
    std::fprintf(csv, "texture,config,width,finest,frame,since_kf,overlap,sigma,passes,ea_x,ea_y,ea_t,A_xx,A_xy,A_xt,"
                      "A_yy,A_yt,A_tt,em_x,em_y,em_t,M_xx,M_xy,M_xt,M_yy,M_yt,M_tt,m_x,m_y,m_t,keyframe\n");
  std::vector<double> all_motion, all_align;
  for (const auto& wh : sizes)
    for (int config : configs)
      for (const std::string& tex : textures) {
        sim::Options so = Scene().options(tex, seconds, wh[0], wh[1], seed);
        so.extrinsics = sim::paper_configuration(config);
        so.pixel_noise = noise;
        const sim::Trajectory traj = sim::generate_trajectory(so);
        const std::vector<sim::Exposure> exposure = sim::exposure_series(so, traj.t);
        sim::Renderer renderer(rt, cv::imread(so.texture, cv::IMREAD_GRAYSCALE), so);
        std::vector<std::unique_ptr<NeesRun>> runs;
        for (int f : finests) {
          track::TrackerOptions o = base;
          o.finest_level = f;
          runs.push_back(std::make_unique<NeesRun>(rt, so, o));
          runs.back()->csv = csv;
          runs.back()->tag = tex + "," + std::to_string(config) + "," + std::to_string(wh[0]) + "," + std::to_string(f);
        }
        for (size_t k = 0; k < traj.t.size(); ++k) {
          const cv::Mat img = bench::camera_frame(renderer, so, traj, exposure, k);
          for (auto& run : runs) run->frame(img, traj.t[k], traj.pose[k == 0 ? 0 : k - 1], traj.pose[k]);
        }
        for (size_t i = 0; i < runs.size(); ++i) {
          const NeesStats& st = runs[i]->st;
          char size[16];
          std::snprintf(size, sizeof size, "%dx%d", wh[0], wh[1]);
          std::printf("%-22s %3d %9s %6d %6d %4d %4d %8.2f %8.2f %9.2f %9.2f %9.2f\n", tex.c_str(), config, size,
                      finests[i], st.frames, st.ok, st.keyframes, NeesStats::mean(st.align), NeesStats::mean(st.motion),
                      NeesStats::mean(st.motion_kf), NeesStats::corr(st.zm_prev, st.zm_cur),
                      NeesStats::corr(st.za_prev, st.za_cur));
          all_motion.push_back(NeesStats::mean(st.motion));
          all_align.push_back(NeesStats::mean(st.align));
        }
        std::fflush(stdout);
      }
  if (csv) std::fclose(csv);
  auto summary = [](const char* what, const std::vector<double>& v) {
    if (v.empty()) return;
    int inside = 0;
    for (double x : v) inside += x >= 2.0 && x <= 4.0;
    std::printf("%s: mean NEES per sequence from %.2f to %.2f (mean %.2f), %d of %zu within [2, 4]\n", what,
                *std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end()), NeesStats::mean(v),
                inside, v.size());
  };
  summary("frame-to-frame motion", all_motion);
  summary("alignment", all_align);
  return 0;
}

// Speed: each scene's frames rendered once into memory, then tracked repeatedly with each
// configuration, the configurations interleaved so that load from other processes spreads over
// all of them; then OpenCV's ECC on pairs of the same frames. Scenes: "mixed" (asphalt_01, the
// mixed drive, every configuration), "fast" (the same texture at 1.5 m/s and 2.5 rad/s) and "car"
// (a rear camera 0.9 m up, 45 degrees down, a car at 3 m/s), the last two with the default and
// level 1 on every pixel (the rule before issue 28) only.
struct SpeedConfig {
  const char* name;
  track::TrackerOptions opt;
  int shutter = 0;  // 0: the global shutter's frames; 1: the rolling shutter's, told; 2: not told
};

std::vector<SpeedConfig> speed_configs() {
  std::vector<SpeedConfig> configs;
  track::TrackerOptions o;
  configs.push_back({"default", o});
  track::TrackerOptions before = o;  // level 1 on every pixel
  before.auto_coarse_block = 0;
  configs.push_back({"level 1 all pixels", before});
  configs.push_back({"rolling shutter 25 ms", o, 1});
  configs.push_back({"rolling 25 ms, not told", o, 2});
  o.photometric.enabled = false;
  configs.push_back({"no photometric model", o});
  o.photometric.enabled = true;
  o.prefilter = false;
  configs.push_back({"no prefilter", o});
  o.prefilter = true;
  o.kernel.lanes = 1;  // the fused pass one pixel at a time, as before float8
  configs.push_back({"per-pixel pass", o});
  track::TrackerOptions h;
  h.finest_level = 1;
  configs.push_back({"half resolution (finest 1)", h});
  h.refine_keyframes = true;
  configs.push_back({"finest 1 + refine keyframes", h});
  track::TrackerOptions f;
  f.finest_level = 0;
  configs.push_back({"full resolution (finest 0)", f});
  f.select_blocks[0] = 4;
  configs.push_back({"level 0 at 1/16 + prior", f});
  f.select_blocks[0] = 2;
  configs.push_back({"level 0 at 1/4 + prior", f});
  track::TrackerOptions l3;
  l3.levels = 3;
  configs.push_back({"3 levels", l3});
  return configs;
}

struct SpeedStats {
  std::vector<double> frame, pipe, track, rest, err_mm;
  std::array<std::vector<double>, track::kMaxLevels> level;
  std::array<double, track::kMaxLevels> level_passes{};
  double cpu = 0, passes = 0;
  int n = 0, lost = 0;
};

// Tracks `frames` with the configurations (all rounds, interleaved) and prints their table.
void speed_table(ocl::Runtime& rt, const std::string& scene, const sim::Options& so, const sim::Trajectory& traj,
                 const std::vector<cv::Mat>& global_frames, const sim::Options* rolling,
                 const std::vector<cv::Mat>* rolling_frames, const std::vector<SpeedConfig>& configs, int rounds,
                 bool paced, std::vector<SpeedStats>* out) {
  std::vector<SpeedStats>& stats = *out;
  stats.assign(configs.size(), SpeedStats());
  for (int round = 0; round < rounds; ++round)
    for (size_t c = 0; c < configs.size(); ++c) {
      if (configs[c].shutter && !rolling_frames) continue;
      const std::vector<cv::Mat>& frames = configs[c].shutter ? *rolling_frames : global_frames;
      track::Tracker tracker(rt, configs[c].shutter == 1 ? rolling->camera : so.camera, so.extrinsics, configs[c].opt);
      const auto start = std::chrono::steady_clock::now();
      for (size_t k = 0; k < frames.size(); ++k) {
        if (paced)  // the frame handed at its time, as a camera would
          std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                    std::chrono::duration<double>(traj.t[k] - traj.t[0])));
        const double c0 = cpu_ms();
        const track::FrameResult r = tracker.track(frames[k].data, frames[k].cols, frames[k].rows, frames[k].step, traj.t[k]);
        if (k == 0) continue;  // the first frame builds the pipeline
        SpeedStats& st = stats[c];
        st.cpu += cpu_ms() - c0;
        st.frame.push_back(r.ms);
        st.pipe.push_back(r.pipeline_ms);
        st.track.push_back(r.ms - r.pipeline_ms);
        for (int p : r.iterations) st.passes += p;
        double in_levels = 0;
        for (size_t l = 0; l < track::kMaxLevels; ++l) {
          st.level[l].push_back(r.level_ms[l]);
          st.level_passes[l] += r.iterations[l];
          in_levels += r.level_ms[l];
        }
        st.rest.push_back(r.ms - r.pipeline_ms - in_levels);
        if (r.status == track::FrameResult::Status::Lost) {
          ++st.lost;
        } else if (round == 0) {
          const SE2 truth = traj.pose[k - 1].inverse() * traj.pose[k];
          st.err_mm.push_back(1000.0 * std::hypot(r.motion.value.x - truth.x, r.motion.value.y - truth.y));
        }
        ++st.n;
      }
    }
  std::printf("\nscene %s: %dx%d, %zu frames x %d rounds, camera-frame API (upload, undistortion, pyramid, "
              "tracking)%s; rms_mm: per-frame translation error against the truth\n",
              scene.c_str(), so.camera.width, so.camera.height, global_frames.size(), rounds,
              paced ? ", frames handed at the camera's rate" : ", frames handed back to back");
  std::printf("%-28s %9s %9s %9s %9s %9s %8s %7s %7s %7s %8s %5s\n", "configuration", "med_frame", "mean_frame",
              "med_pipe", "med_track", "cpu/frame", "passes", "fps", "p99/md", "max/md", "rms_mm", "lost");
  for (size_t c = 0; c < configs.size(); ++c) {
    const SpeedStats& st = stats[c];
    if (st.n == 0) continue;
    double mean = 0, ss = 0;
    for (double v : st.frame) mean += v;
    mean /= std::max<size_t>(1, st.frame.size());
    for (double e : st.err_mm) ss += e * e;
    const Tail t = tail(st.frame);
    std::printf("%-28s %9.2f %9.2f %9.2f %9.2f %9.2f %8.2f %7.0f %7.2f %7.2f %8.4f %5d\n", configs[c].name, t.median,
                mean, median(st.pipe), median(st.track), st.cpu / st.n, st.passes / st.n, 1000.0 / mean,
                t.p99_over_median, t.max_over_median, std::sqrt(ss / std::max<size_t>(1, st.err_mm.size())),
                st.lost / rounds);
  }
  std::printf("where the tracking time goes (medians, ms; passes per frame in brackets; rest: outside the levels)\n");
  std::printf("%-28s", "configuration");
  for (int l = 3; l >= 0; --l) std::printf("   level %d      ", l);
  std::printf("%8s\n", "rest");
  for (size_t c = 0; c < configs.size(); ++c) {
    const SpeedStats& st = stats[c];
    if (st.n == 0) continue;
    std::printf("%-28s", configs[c].name);
    for (int l = 3; l >= 0; --l)
      std::printf(" %6.2f (%5.2f)  ", median(st.level[static_cast<size_t>(l)]),
                  st.level_passes[static_cast<size_t>(l)] / st.n);
    std::printf("%8.2f\n", median(st.rest));
  }
  std::fflush(stdout);
}

// OpenCV's ECC (homography, 3 levels, bench_ecc.h) on `pairs` pairs (k, k+1) spread over the
// frames, undistorted with cv::remap first (not timed): the median time per pair.
double ecc_median_ms(const sim::Options& so, const std::vector<cv::Mat>& frames, int pairs) {
  const bench::EccFrames ecc_frames(so.camera);
  std::vector<double> ms;
  const size_t n = frames.size();
  for (int i = 0; i < pairs; ++i) {
    const size_t k = 1 + static_cast<size_t>(i) * (n - 3) / static_cast<size_t>(std::max(1, pairs - 1));
    const cv::Mat a = ecc_frames.undistort(frames[k]), b = ecc_frames.undistort(frames[k + 1]);
    cv::Mat H;
    const double t0 = bench::now_ms();
    bench::ecc_pair(a, b, ecc_frames.mask, 3, &H);
    ms.push_back(bench::now_ms() - t0);
  }
  return median(ms);
}

int bench_speed(int width, int height, double seconds, int rounds, const std::string& only,
                const std::string& scene_names, bool paced) {
  ocl::Runtime rt;
  std::printf("device: %s\n", rt.device_info().device_name.c_str());
  const std::vector<SpeedConfig> all = speed_configs();
  std::vector<SpeedConfig> configs = all;
  if (!only.empty()) {  // a comma-separated list of configuration numbers (from 0)
    configs.clear();
    for (const std::string& i : bench::split(only)) configs.push_back(all.at(static_cast<size_t>(std::atoi(i.c_str()))));
  }
  const std::vector<SpeedConfig> two(all.begin(), all.begin() + 2);  // the default and level 1 on every pixel
  struct SceneSpec {
    const char* name;
    Scene scene;
  };
  std::vector<SceneSpec> scenes(3);
  scenes[0].name = "mixed";
  scenes[1].name = "fast";
  scenes[1].scene.speed = 1.5;
  scenes[1].scene.turn = 2.5;
  scenes[2].name = "car";
  scenes[2].scene.parse("ext", "0,0,0.9,0,45,0");
  scenes[2].scene.parse("motion", "car");
  scenes[2].scene.speed = 3.0;
  std::vector<std::string> summary;
  for (size_t i = 0; i < scenes.size(); ++i) {
    if (!scene_names.empty() && ("," + scene_names + ",").find(std::string(",") + scenes[i].name + ",") == std::string::npos)
      continue;
    const sim::Options so = scenes[i].scene.options("asphalt_01.png", seconds, width, height, 1);
    const sim::Trajectory traj = sim::generate_trajectory(so);
    const std::vector<cv::Mat> frames = bench::render_sequence(rt, so, traj);
    std::vector<SpeedStats> stats;
    const std::vector<SpeedConfig>& run = i == 0 ? configs : two;
    if (i == 0) {
      // The same drive through a rolling shutter read out over 25 ms.
      sim::Options rolling = so;
      rolling.readout_time = rolling.camera.rolling_shutter_readout = 0.025;
      const std::vector<cv::Mat> rolling_frames = bench::render_sequence(rt, rolling, traj);
      speed_table(rt, scenes[i].name, so, traj, frames, &rolling, &rolling_frames, run, rounds, paced, &stats);
    } else {
      speed_table(rt, scenes[i].name, so, traj, frames, nullptr, nullptr, run, rounds, paced, &stats);
    }
    const double ecc = ecc_median_ms(so, frames, 20);
    const double def = tail(stats[0].frame).median;
    char line[200];
    std::snprintf(line, sizeof line, "%-6s  ECC %8.1f ms per pair (median of 20)   %s %6.2f ms   ECC / %s %6.1fx",
                  scenes[i].name, ecc, run[0].name, def, run[0].name, ecc / std::max(1e-9, def));
    std::printf("%s\n", line);
    summary.push_back(line);
  }
  std::printf("\nOpenCV ECC (homography, 3 levels, on frames undistorted beforehand) on the same frames:\n");
  for (const std::string& l : summary) std::printf("%s\n", l.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "kernel";
  if (mode == "kernel") {
    const int w = argc > 3 ? std::atoi(argv[2]) : 640, h = argc > 3 ? std::atoi(argv[3]) : 480;
    std::vector<KernelConfig> only;
    // bench_track kernel [w h [wg_x wg_y pix hist fast lanes [rounds]]]
    if (argc > 9)
      only.push_back({std::atoi(argv[4]), std::atoi(argv[5]), std::atoi(argv[6]), std::atoi(argv[7]), std::atoi(argv[8]) != 0,
                      std::atoi(argv[9])});
    return bench_kernel(w, h, only, argc > 10 ? std::atoi(argv[10]) : 6);
  }
  if (mode == "speed") {
    // bench_track speed [w h] [seconds] [rounds] [configs] [scenes] [paced]
    const int w = argc > 3 ? std::atoi(argv[2]) : 640, h = argc > 3 ? std::atoi(argv[3]) : 480;
    return bench_speed(w, h, argc > 4 ? std::atof(argv[4]) : 5.0, argc > 5 ? std::atoi(argv[5]) : 3,
                       argc > 6 ? argv[6] : "", argc > 7 ? argv[7] : "", argc > 8 && std::atoi(argv[8]) != 0);
  }
  if (mode == "accuracy") {
    // bench_track accuracy [key=value ...]: seconds=10 w=640 h=480 levels=4 finest=0
    //   refine_kf=0 maxit=a,b,c,d (per level from 0) textures=a.png,b.png seed=1
    double seconds = 10.0;
    int w = 640, h = 480;
    uint64_t seed = 1;
    Scene scene;
    bool perturb = false;
    track::TrackerOptions topt;
    std::vector<std::string> tex = {"asphalt_01.png", "anti_skid_tiles.png", "brick_floor.png",
                                    "aerial_ground_rock.png"};
    for (int i = 2; i < argc; ++i) {
      const std::string a = argv[i];
      const size_t eq = a.find('=');
      const std::string k = a.substr(0, eq), v = eq == std::string::npos ? "" : a.substr(eq + 1);
      if (k == "seconds") seconds = std::atof(v.c_str());
      else if (k == "w") w = std::atoi(v.c_str());
      else if (k == "h") h = std::atoi(v.c_str());
      else if (k == "perturb") perturb = std::atoi(v.c_str()) != 0;
      else if (k == "seed") seed = std::strtoull(v.c_str(), nullptr, 10);
      else if (scene.parse(k, v)) continue;
      else if (k == "levels") topt.levels = std::atoi(v.c_str());
      else if (k == "finest") topt.finest_level = std::atoi(v.c_str());
      else if (k == "refine_kf") topt.refine_keyframes = std::atoi(v.c_str()) != 0;
      else if (k == "select") {  // per level, finest first: select=4,2
        const auto b = split(v);
        for (size_t l = 0; l < b.size() && l < topt.select_blocks.size(); ++l) topt.select_blocks[l] = std::atoi(b[l].c_str());
      }
      else if (k == "coarse_block") topt.auto_coarse_block = std::atoi(v.c_str());
      else if (k == "prior") topt.subsample_prior = std::atoi(v.c_str()) != 0;
      else if (k == "prior_chi2") topt.prior_chi2 = std::atof(v.c_str());
      else if (k == "prefilter") topt.prefilter = v != "0";
      else if (k == "photometric") topt.photometric.enabled = v != "0";
      else if (k == "search") topt.search_motion = v != "0";
      else if (k == "learn") topt.photometric.learn = v != "0";
      else if (k == "saturation") topt.photometric.saturation = std::atof(v.c_str());
      else if (k == "photo_radius") topt.photometric.radius = std::atoi(v.c_str());
      else if (k == "photo_min") topt.photometric.min_frames = std::atoi(v.c_str());
      else if (k == "max_tex") topt.max_texture_residual = std::atof(v.c_str());
      else if (k == "unroll") g_tracker_knows_readout = v != "0";
      else if (k == "told_exposure") g_told_exposure = std::atof(v.c_str());
      else if (k == "told_readout") g_told_readout = std::atof(v.c_str());
      else if (k == "rs_tol") topt.rolling_shutter_tolerance_px = std::atof(v.c_str());
      else if (k == "lanes") topt.kernel.lanes = std::atoi(v.c_str());
      else if (k == "pix") topt.kernel.pixels_per_item = std::atoi(v.c_str());
      else if (k == "wg") {  // wg=16x4
        const size_t x = v.find('x');
        topt.kernel.wg_x = std::atoi(v.substr(0, x).c_str());
        topt.kernel.wg_y = x == std::string::npos ? 1 : std::atoi(v.substr(x + 1).c_str());
      }
      else if (k == "conv") topt.convergence_px = std::atof(v.c_str());
      else if (k == "huber") topt.huber_factor = std::atof(v.c_str());
      else if (k == "brightness") topt.estimate_brightness = v != "0";
      else if (k == "decorrelate") topt.decorrelate_noise = v != "0";
      else if (k == "plane") topt.local_plane = v != "0";
      else if (k == "mounting") {  // mounting=recalibrate|report|ignore
        using R = track::TrackerOptions::MountingResponse;
        topt.on_mounting_change = v == "ignore" ? R::Ignore : v == "report" ? R::Report : R::Recalibrate;
      } else if (k == "plane_width") topt.attitude_max_width = std::atoi(v.c_str());
      else if (k == "plane_sigma") topt.local_plane_prior_sigma = std::atof(v.c_str()) * M_PI / 180.0;
      else if (k == "kf_scale") topt.keyframe_scale_change = std::atof(v.c_str());
      else if (k == "overlap") topt.keyframe_overlap = std::atof(v.c_str());
      else if (k == "maxit") {
        const auto it = split(v);
        for (size_t l = 0; l < it.size() && l < topt.max_iterations.size(); ++l) topt.max_iterations[l] = std::atoi(it[l].c_str());
      } else if (k == "textures") tex = split(v);
      else {
        std::fprintf(stderr, "unknown option %s\n", a.c_str());
        return 2;
      }
    }
    if (tex.size() == 1 && tex[0] == "all") tex = all_textures();
    return bench_accuracy(tex, seconds, w, h, seed, scene, perturb, topt, std::getenv("BENCH_VERBOSE") != nullptr);
  }
  if (mode == "nees") {
    // bench_track nees [key=value ...]: seconds=5 textures=a.png,b.png|all configs=1,2,3
    //   sizes=640x480,320x240 finest=0,1 seed=1 (every texture x configuration x size, each
    //   sequence rendered once and tracked once per finest level)
    double seconds = 5.0, noise = 1.0;
    uint64_t seed = 1;
    std::vector<std::string> tex = {"asphalt_01.png", "anti_skid_tiles.png", "brick_floor.png",
                                    "aerial_ground_rock.png"};
    std::vector<int> configs = {1, 2, 3}, finests = {0, 1};
    std::vector<std::array<int, 2>> sizes = {{640, 480}, {320, 240}};
    track::TrackerOptions topt;
    for (int i = 2; i < argc; ++i) {
      const std::string a = argv[i];
      const size_t eq = a.find('=');
      const std::string k = a.substr(0, eq), v = eq == std::string::npos ? "" : a.substr(eq + 1);
      if (k == "seconds") seconds = std::atof(v.c_str());
      else if (k == "seed") seed = std::strtoull(v.c_str(), nullptr, 10);
      else if (k == "noise") noise = std::atof(v.c_str());
      else if (k == "coarse_block") topt.auto_coarse_block = std::atoi(v.c_str());
      else if (k == "prior") topt.subsample_prior = std::atoi(v.c_str()) != 0;
      else if (k == "prior_chi2") topt.prior_chi2 = std::atof(v.c_str());
      else if (k == "prefilter") topt.prefilter = v != "0";
      else if (k == "conv") topt.convergence_px = std::atof(v.c_str());
      else if (k == "huber") topt.huber_factor = std::atof(v.c_str());
      else if (k == "brightness") topt.estimate_brightness = std::atoi(v.c_str()) != 0;
      else if (k == "step_fraction") topt.covariance_step_fraction = std::atof(v.c_str());
      else if (k == "rho") topt.consecutive_alignment_correlation = std::atof(v.c_str());
      else if (k == "maxit") {
        const auto it = split(v);
        for (size_t l = 0; l < it.size() && l < topt.max_iterations.size(); ++l) topt.max_iterations[l] = std::atoi(it[l].c_str());
      } else if (k == "textures") tex = v == "all" ? all_textures() : split(v);
      else if (k == "configs" || k == "finest") {
        std::vector<int>& out = k == "configs" ? configs : finests;
        out.clear();
        for (const std::string& x : split(v)) out.push_back(std::atoi(x.c_str()));
      } else if (k == "sizes") {
        sizes.clear();
        for (const std::string& x : split(v)) {
          int w = 0, h = 0;
          if (std::sscanf(x.c_str(), "%dx%d", &w, &h) != 2 || w < 16 || h < 16) {
            std::fprintf(stderr, "bad size %s (WxH)\n", x.c_str());
            return 2;
          }
          sizes.push_back({w, h});
        }
      } else {
        std::fprintf(stderr, "unknown option %s\n", a.c_str());
        return 2;
      }
    }
    for (int c : configs)
      if (c < 1 || c > 3) {
        std::fprintf(stderr, "configs must be 1, 2 or 3\n");
        return 2;
      }
    return bench_nees(tex, configs, sizes, finests, seconds, seed, noise, topt);
  }
  std::fprintf(stderr, "usage: bench_track kernel [w h [wx wy pix hist fast [rounds]]] | speed [w h [seconds [rounds [configs [scenes [paced]]]]]]"
                       " | accuracy [key=value...] | nees [key=value...]\n");
  return 2;
}
