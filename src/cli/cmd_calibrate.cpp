// `planarvo calibrate DATASET`: the camera's extrinsics from a short drive (roll and pitch from
// images, then x, y, height and yaw from the graph), through planarvo_calibrate_dataset.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common.h"

namespace planarvo::cli {
namespace {

constexpr double kDeg = M_PI / 180.0;

void print_result(const planarvo_camera_calibration_result& r) {
  std::printf("camera extrinsics (T_robot_camera; metres and radians in the file):\n");
  const double v[6] = {r.extrinsics.x, r.extrinsics.y, r.extrinsics.z, r.extrinsics.roll, r.extrinsics.pitch,
                       r.extrinsics.yaw};
  for (int i = 0; i < 6; ++i) {
    const bool angle = i >= 3;
    const double k = angle ? 1 / kDeg : 1e3;
    const char* unit = angle ? "deg" : "mm";
    const double sd = std::sqrt(std::max(0.0, r.covariance[i * 7]));
    if (!r.estimated[i]) {
      std::printf("  %-5s %10.3f %-3s  (given, not estimated)\n", planarvo_extrinsics_name(i), v[i] * k, unit);
      continue;
    }
    std::printf("  %-5s %10.3f %-3s  +- %.3f%s\n", planarvo_extrinsics_name(i), v[i] * k, unit, sd * k,
                r.observable[i] ? "" : "  NOT DETERMINED");
  }
}

}  // namespace

planarvo_status calibrate_dataset(planarvo_context* ctx, planarvo_dataset* ds,
                                  planarvo_camera_calibration_options* options, Progress* progress,
                                  planarvo_camera_calibration_result* result) {
  options->progress = &Progress::callback;
  options->progress_user_data = progress;
  result->struct_size = sizeof *result;
  const planarvo_status st = planarvo_calibrate_dataset(ctx, ds, options, result);
  progress->finish();
  if (st != PLANARVO_OK && st != PLANARVO_ERROR_FAILED) check(st);
  return st;
}

int cmd_calibrate_dataset(const Args& args, const planarvo_calibration_options& graph) {
  const std::string dir = args.positionals()[0];
  planarvo_camera_calibration_options o;
  planarvo_camera_calibration_options_init(&o);
  const std::string method = args.get("method", "odometry");  // as the user wrote it, for the output
  o.method = graph.method;
  // The odometry's noise model is the workflow's default (fitted to the drive's residuals: the
  // camera's motions are far more precise than wheel odometry) unless the user gave one.
  planarvo_calibration_options g = graph;
  if (args.has("odometry-sigma")) g.estimate_odometry_noise = 0;
  o.graph = &g;
  if (args.has("fix-scale")) throw UsageError("--fix-scale is for metric sensors' motion pairs; give --height METRES");
  if (args.has("initial")) throw UsageError("--initial is for motion pairs; give --initial-extrinsics FILE");
  o.accept_unusual_extrinsics = args.has("force") ? 1 : 0;
  if (args.has("height")) {
    o.height = args.get_double("height", 0);
    if (!(o.height > 0)) throw UsageError("--height must be a positive number of metres");
  }
  if (args.has("frames")) {
    const long long n = args.get_int("frames", 0);
    if (n < 1) throw UsageError("--frames must be at least 1");
    o.roll_pitch_frames = static_cast<int32_t>(n);
  }
  if (args.has("initial-extrinsics")) {
    check(planarvo_extrinsics_load(args.get("initial-extrinsics").c_str(), &o.initial));
    o.has_initial = 1;
  }
  args.expect_output_files({"output"});
  const std::optional<planarvo_region> roi = parse_roi(args);  // before any file is read
  const bool estimate_readout = args.get("readout-time", "") == "estimate";
  const std::optional<double> readout = estimate_readout ? std::nullopt : parse_readout(args);
  if (estimate_readout) o.readout = PLANARVO_READOUT_ESTIMATE;
  const std::string out = args.get("output");
  ContextPtr ctx = make_context(args);
  Progress progress(!args.has("quiet"));
  DatasetPtr ds = open_dataset(dir, args, false, &progress);
  apply_roi(roi, ds.get());
  apply_readout(readout, ds.get());
  planarvo_camera_calibration_result r{};
  const planarvo_status st = calibrate_dataset(ctx.get(), ds.get(), &o, &progress, &r);

  std::printf("calibrated %s (%s) on %s\n", dir.c_str(), method.c_str(), device_name(ctx.get()).c_str());
  if (o.method == PLANARVO_CALIBRATE_NONHOLONOMIC) {
    planarvo_dataset_info info{};
    info.struct_size = sizeof info;
    check(planarvo_dataset_info_get(ds.get(), &info));
    if (!info.has_direction)
      std::printf("direction labels: none in %s; taken from the wheel odometry's sign (forward +1, backward -1)\n",
                  dir.c_str());
  }
  if (r.roll_pitch.status == PLANARVO_CALIBRATION_OK && r.roll_pitch.keyframes > 0)
    std::printf("roll and pitch: %d keyframes (%d pairs) from %d frames, %.2f s\n", r.roll_pitch.keyframes,
                r.roll_pitch.pairs, r.roll_pitch.frames_used, r.seconds_roll_pitch);
  if (r.frames > 0)
    std::printf("tracking: %d frames, %d ok, %d degraded, %d lost; %d intervals; median %.2f ms per frame, %.2f s\n",
                r.frames, r.frames_ok, r.frames_degraded, r.frames_lost, r.samples, r.tracking_median_ms,
                r.seconds_tracking);
  if (r.samples > 0)
    std::printf("graph calibration: %d iterations over all solves, %d gross errors gated, variance factor %.3g, "
                "%.3f s\n",
                r.graph.total_iterations, r.graph.outliers, r.graph.variance_factor, r.seconds_graph);
  if (r.readout_evaluations > 0 && r.readout_reason[0] == 0)
    std::printf("rolling shutter: readout %.2f ms +- %.2f estimated from %d frames (%d candidates), %.2f s; %s\n",
                r.readout_estimate * 1e3, r.readout_sigma * 1e3, r.readout_frames, r.readout_evaluations,
                r.seconds_readout, r.readout > 0 ? "used" : "within 2 sigma of 0: a global shutter");
  else if (r.readout_evaluations > 0 || r.readout_reason[0] != 0)
    std::printf("rolling shutter: the readout time could not be estimated (%s); %.2f ms used\n", r.readout_reason,
                r.readout * 1e3);
  std::printf("time: %.2f s in all (%.2f s waiting for images)\n", r.seconds_total, r.seconds_decode);
  if (st == PLANARVO_OK || r.status == PLANARVO_CALIBRATION_UNOBSERVABLE) print_result(r);
  if (st == PLANARVO_ERROR_FAILED) {
    std::fprintf(stderr, "planarvo calibrate: %s\n", r.reason);
    if (!out.empty()) std::fprintf(stderr, "planarvo calibrate: %s not written\n", out.c_str());
    return kExitFailed;
  }
  if (!out.empty()) {
    check(planarvo_camera_calibration_save(out.c_str(), &r, ("planarvo calibrate " + dir).c_str()));
    std::printf("wrote %s\n", out.c_str());
  }
  return kExitOk;
}

}  // namespace planarvo::cli
