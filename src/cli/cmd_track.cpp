// `planarvo track`: dense planar visual odometry over a data set.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "common.h"

namespace planarvo::cli {
namespace {

constexpr double kDeg = M_PI / 180.0;

const char* status_label(planarvo_track_status s) {
  switch (s) {
    case PLANARVO_TRACK_FIRST: return "first";
    case PLANARVO_TRACK_OK: return "ok";
    case PLANARVO_TRACK_DEGRADED: return "degraded";
    case PLANARVO_TRACK_LOST: return "lost";
  }
  return "?";
}

// A stats file left unfinished by an error is removed, not completed (close() completes it).
struct StatsDiscarder {
  void operator()(planarvo_stats_writer* w) const { planarvo_stats_writer_discard(w); }
};
struct TrackerDeleter {
  void operator()(planarvo_tracker* t) const { planarvo_tracker_destroy(t); }
};

// The tracked frames of a run (a skipped frame has none), for the trajectory, the motion pairs
// and the accuracy.
struct Tracked {
  std::vector<double> t;
  std::vector<planarvo_se2> pose, motion, truth;
  std::vector<planarvo_track_status> status;
  std::vector<planarvo_plane_attitude> plane;  // the local plane's attitude per frame
  bool all_truth = true;
};

// The motion pair of a tracked interval, with the data set's odometry and direction label when
// it has them; none for an interval the odometry or the labels do not cover, so that every row
// has the same columns. The sensor's motion is the camera's own (planarvo_sensor_motion: its
// ground point and yaw, in units of its height), whatever extrinsics the robot's was tracked with,
// which is what calibrate --motions calibrates.
bool motion_pair(const planarvo_dataset_info& info, const planarvo_extrinsics& extrinsics,
                 const planarvo_frame_data& previous, const planarvo_frame_data& fd, const planarvo_track_result& r,
                 planarvo_motion_pair* p) {
  if (r.status != PLANARVO_TRACK_OK && r.status != PLANARVO_TRACK_DEGRADED) return false;
  if (info.has_odometry && !(fd.has_odometry && previous.has_odometry)) return false;
  if (info.has_direction && !fd.has_direction) return false;
  planarvo_motion_pair_init(p);
  p->interval = fd.timestamp - previous.timestamp;
  check(planarvo_sensor_motion(&extrinsics, &r.motion, r.covariance, &p->sensor, p->sensor_covariance));
  p->has_sensor_covariance = 1;
  p->has_odometry = info.has_odometry;
  if (p->has_odometry) p->odometry = relative(previous.odometry, fd.odometry);
  p->has_direction = info.has_direction;
  p->direction = fd.direction;
  return p->interval > 0;
}

planarvo_frame_stats stats_row(const planarvo_frame_data& fd, double dt, const planarvo_track_result& r) {
  planarvo_frame_stats row{};
  row.timestamp = fd.timestamp;
  row.vx = dt > 0 ? r.motion.x / dt : 0;
  row.vy = dt > 0 ? r.motion.y / dt : 0;
  row.omega = dt > 0 ? r.motion.theta / dt : 0;
  for (int l = 0; l < 8; ++l) row.iterations += r.iterations[l];
  row.final_cost = r.final_cost;
  row.inlier_fraction = r.inlier_fraction;
  row.ms = r.ms;
  row.status = status_label(r.status);
  return row;
}

void count(const planarvo_track_result& r, TrackRun* run) {
  ++run->frames;
  run->ms.push_back(r.ms);
  run->engine_ms += r.ms;
  run->keyframes += r.keyframe ? 1 : 0;
  if (r.status == PLANARVO_TRACK_OK || r.status == PLANARVO_TRACK_FIRST) ++run->ok;
  if (r.status == PLANARVO_TRACK_DEGRADED) ++run->degraded;
  if (r.status == PLANARVO_TRACK_LOST) ++run->lost;
  if (r.status != PLANARVO_TRACK_LOST && !r.attitude_observed) ++run->attitude_unobserved;
}

// Status group of an interval for the accuracy by status: 0 Ok (First cannot end one), 1
// Degraded, 2 Lost.
int status_group(planarvo_track_status s) {
  return s == PLANARVO_TRACK_DEGRADED ? 1 : s == PLANARVO_TRACK_LOST ? 2 : 0;
}

// Lost frames in time: each Lost frame's interval since the previous tracked frame, and the
// longest run of consecutive Lost frames.
void account_lost(const Tracked& k, TrackRun* run) {
  int64_t run_frames = 0;
  double run_seconds = 0, run_start = 0;
  for (size_t i = 0; i < k.t.size(); ++i) {
    if (k.status[i] != PLANARVO_TRACK_LOST) {
      run_frames = 0;
      run_seconds = 0;
      continue;
    }
    const double dt = i > 0 ? k.t[i] - k.t[i - 1] : 0.0;
    run->lost_seconds += dt;
    if (run_frames == 0) run_start = k.t[i];
    ++run_frames;
    run_seconds += dt;
    if (run_frames > run->longest_lost_run) {
      run->longest_lost_run = run_frames;
      run->longest_lost_seconds = run_seconds;
      run->longest_lost_start = run_start;
    }
  }
}

// The accuracy over every interval (whatever its status: a Lost interval's motion is the
// tracker's prediction, and it is part of the trajectory), then per status.
void evaluate(const Tracked& k, TrackRun* run) {
  const size_t n = k.t.size();
  if (!k.all_truth || n < 2) return;
  std::vector<planarvo_se2> est(n - 1), tru(n - 1);
  std::vector<double> dt(n - 1);
  for (size_t i = 1; i < n; ++i) {
    est[i - 1] = k.motion[i];
    tru[i - 1] = relative(k.truth[i - 1], k.truth[i]);
    dt[i - 1] = k.t[i] - k.t[i - 1];
  }
  run->accuracy.struct_size = sizeof run->accuracy;
  check(planarvo_evaluate_motions(est.data(), tru.data(), dt.data(), nullptr, n - 1, 1e-3, &run->accuracy));
  std::vector<int32_t> in_group(n - 1);
  for (int g = 0; g < 3; ++g) {
    for (size_t i = 1; i < n; ++i) in_group[i - 1] = status_group(k.status[i]) == g;
    run->by_status[g].struct_size = sizeof run->by_status[g];
    check(planarvo_evaluate_motions(est.data(), tru.data(), dt.data(), in_group.data(), n - 1, 1e-3,
                                    &run->by_status[g]));
  }
  run->has_accuracy = true;
}

// The warning line for a change of the mounting: when, by how much, and what was done.
std::string mounting_warning(const planarvo_track_result& r, double origin, double t, int32_t response) {
  const planarvo_extrinsics& m = r.changed_mounting;
  char z[200] = "";
  if (std::isfinite(r.mounting_step_sigma[2]))
    std::snprintf(z, sizeof z, ", yaw %+.2f +- %.2f deg (the direction of travel)", r.mounting_step[2] / kDeg,
                  r.mounting_step_sigma[2] / kDeg);
  if (std::isfinite(r.mounting_step_sigma[3]))
    std::snprintf(z + std::strlen(z), sizeof z - std::strlen(z),
                  ", the camera's height by %+.1f +- %.1f mm (against the wheel odometry)", r.mounting_step[3] * 1e3,
                  r.mounting_step_sigma[3] * 1e3);
  const std::string height = z;
  char line[640];
  std::snprintf(line, sizeof line,
                "planarvo track: warning: the camera's mounting changed at t = %.3f s (%s at %.3f s): the body's "
                "attitude stepped by roll %+.2f +- %.2f deg, pitch %+.2f +- %.2f deg%s and held; %s %.4f,%.4f,%.4f,"
                "%.3f,%.3f,%.3f (x,y,z m; roll,pitch,yaw deg)",
                origin + r.mounting_change_time,
                r.mounting_refinement ? "measured once more with the recalibrated mounting" : "found", origin + t,
                r.mounting_step[0] / kDeg, r.mounting_step_sigma[0] / kDeg,
                r.mounting_step[1] / kDeg, r.mounting_step_sigma[1] / kDeg, height.c_str(),
                response == PLANARVO_MOUNTING_RECALIBRATE ? "tracking on with the mounting"
                                                          : "kept the mounting given (--mounting-change report); the "
                                                            "images say",
                m.x, m.y, m.z, m.roll / kDeg, m.pitch / kDeg, m.yaw / kDeg);
  return line;
}

}  // namespace

namespace {

// A warning beside the progress bar, or on stderr without one.
void warn(Progress* progress, const std::string& warning) {
  if (progress) progress->warn(warning);
  else std::fprintf(stderr, "%s\n", warning.c_str());
}

// The files `track` writes once the frames are tracked.
void write_outputs(const TrackOutputs& outputs, const Tracked& k, double origin, const TrackRun& run,
                   const planarvo_extrinsics& mounting, const std::vector<planarvo_motion_pair>& pairs,
                   planarvo_tracker* tracker, Progress* progress) {
  if (!outputs.trajectory.empty()) {
    std::vector<double> stamps(k.t);
    for (double& t : stamps) t += origin;
    check(planarvo_write_tum(outputs.trajectory.c_str(), stamps.data(), k.pose.data(), k.t.size()));
  }
  if (!outputs.plane.empty()) check(planarvo_write_plane(outputs.plane.c_str(), k.plane.data(), k.plane.size()));
  if (!outputs.mounting.empty()) {
    const std::string note = run.mounting_changes > 0
                                 ? "the mounting after the last change the local plane found while tracking"
                                 : "the mounting given: no change found while tracking";
    check(planarvo_extrinsics_save(outputs.mounting.c_str(), &mounting, nullptr, nullptr, "track --local-plane",
                                   note.c_str()));
  }
  if (!outputs.motions.empty()) check(planarvo_motion_pairs_save(outputs.motions.c_str(), pairs.data(), pairs.size()));
  if (!outputs.flat_field.empty()) {
    const planarvo_status s = planarvo_tracker_save_flat_field(tracker, outputs.flat_field.c_str());
    if (s == PLANARVO_ERROR_FAILED) {
      warn(progress, std::string("planarvo track: warning: ") + planarvo_last_error());
    } else {
      check(s);
    }
  }
}

// The body's lean in turns fitted to the local plane's attitudes (planarvo_fit_body_lean).
void fit_lean(const Tracked& k, TrackRun* run) {
  std::vector<double> roll(k.t.size()), pitch(k.t.size());
  std::vector<int32_t> use(k.t.size());
  for (size_t i = 0; i < k.t.size(); ++i) {
    roll[i] = k.plane[i].roll;
    pitch[i] = k.plane[i].pitch;
    use[i] = k.status[i] == PLANARVO_TRACK_OK || k.status[i] == PLANARVO_TRACK_DEGRADED;
  }
  run->lean.struct_size = sizeof run->lean;
  check(planarvo_fit_body_lean(k.t.data(), k.motion.data(), roll.data(), pitch.data(), use.data(), k.t.size(),
                               &run->lean));
  run->has_lean = true;
}

// The statistics row of a tracked frame (with the local plane's attitude when it is estimated).
planarvo_frame_stats frame_row(const planarvo_frame_data& fd, double dt, const planarvo_track_result& r,
                               double origin, bool local_plane) {
  planarvo_frame_stats row = stats_row(fd, dt, r);
  row.timestamp += origin;
  if (local_plane) {
    row.has_attitude = 1;
    row.roll = r.roll;
    row.pitch = r.pitch;
    row.sigma_roll = std::sqrt(std::max(0.0, r.attitude_covariance[0]));
    row.sigma_pitch = std::sqrt(std::max(0.0, r.attitude_covariance[3]));
    row.mounting_changed = r.mounting_changed;
  }
  return row;
}

}  // namespace

TrackRun track_dataset(planarvo_context* ctx, planarvo_dataset* ds, const planarvo_extrinsics& extrinsics,
                       const planarvo_tracker_options& options, const TrackOutputs& outputs, Progress* progress) {
  planarvo_dataset_info info{};
  info.struct_size = sizeof info;
  check(planarvo_dataset_info_get(ds, &info));
  planarvo_tracker* raw = nullptr;
  check(planarvo_tracker_create(ctx, &info.camera, &extrinsics, &options, &raw));
  std::unique_ptr<planarvo_tracker, TrackerDeleter> tracker(raw);
  std::unique_ptr<planarvo_stats_writer, StatsDiscarder> stats;
  if (!outputs.stats.empty()) {
    planarvo_stats_writer* w = nullptr;
    check(planarvo_stats_writer_open(outputs.stats.c_str(), &w));
    stats.reset(w);
  }
  // A bag's times are seconds after its first frame (exact differences); the files get the
  // stamps back (to about 0.2 microseconds at today's epoch).
  const double origin = static_cast<double>(info.time_origin_ns) * 1e-9;
  TrackRun run;
  Tracked k;
  std::vector<planarvo_motion_pair> pairs;
  planarvo_frame_data previous{};  // the last tracked frame's
  planarvo_extrinsics mounting = extrinsics;  // as the images last said
  const auto n = static_cast<size_t>(info.frame_count);
  for (size_t i = 0; i < n; ++i) {
    if (progress) Progress::callback(progress, static_cast<double>(i) / static_cast<double>(n), "tracking");
    planarvo_frame_data fd{};
    check(planarvo_dataset_frame_data(ds, static_cast<int64_t>(i), &fd));
    planarvo_image img{};
    const planarvo_status read = planarvo_dataset_frame(ds, static_cast<int64_t>(i), &img);
    if (read == PLANARVO_ERROR_INVALID_INPUT && outputs.skip_bad_frames) {
      warn(progress, "planarvo track: skipping frame " + std::to_string(i) + ": " + planarvo_last_error());
      ++run.skipped;
      if (stats) {
        planarvo_frame_stats row{};
        row.timestamp = origin + fd.timestamp;
        row.status = "skipped";
        check(planarvo_stats_writer_add(stats.get(), &row));
      }
      continue;
    }
    check(read);
    planarvo_track_result r{};
    r.struct_size = sizeof r;
    if (fd.has_odometry) check(planarvo_tracker_odometry(tracker.get(), &fd.odometry));
    check(planarvo_tracker_track(tracker.get(), &img, fd.timestamp, &r));
    count(r, &run);
    if (r.mounting_changed) {
      ++run.mounting_changes;
      mounting = r.changed_mounting;
      warn(progress, mounting_warning(r, origin, fd.timestamp, options.on_mounting_change));
    }
    const bool first = k.t.empty();
    if (stats) {
      const planarvo_frame_stats row = frame_row(fd, first ? 0 : fd.timestamp - k.t.back(), r, origin, options.local_plane != 0);
      check(planarvo_stats_writer_add(stats.get(), &row));
    }
    planarvo_motion_pair p;
    if (!outputs.motions.empty() && !first && motion_pair(info, extrinsics, previous, fd, r, &p))
      pairs.push_back(p);
    k.t.push_back(fd.timestamp);
    k.pose.push_back(r.pose);
    k.motion.push_back(r.motion);
    k.status.push_back(r.status);
    k.plane.push_back({origin + fd.timestamp, r.roll, r.pitch, std::sqrt(std::max(0.0, r.attitude_covariance[0])),
                       std::sqrt(std::max(0.0, r.attitude_covariance[3]))});
    k.truth.push_back(fd.groundtruth);
    k.all_truth = k.all_truth && fd.has_groundtruth;
    previous = fd;
  }
  if (progress) Progress::callback(progress, 1.0, "tracking");
  if (stats) check(planarvo_stats_writer_close(stats.release()));
  write_outputs(outputs, k, origin, run, mounting, pairs, tracker.get(), progress);
  account_lost(k, &run);
  evaluate(k, &run);
  if (options.local_plane && k.t.size() >= 3) fit_lean(k, &run);
  return run;
}

double median_ms(const TrackRun& run) {
  std::vector<double> ms = run.ms;
  std::sort(ms.begin(), ms.end());
  return ms.empty() ? 0 : ms[ms.size() / 2];
}

void print_track_run(const TrackRun& run) {
  const double median = median_ms(run);
  std::printf("frames %lld: %lld ok, %lld degraded, %lld lost; %lld keyframes\n", static_cast<long long>(run.frames),
              static_cast<long long>(run.ok), static_cast<long long>(run.degraded), static_cast<long long>(run.lost),
              static_cast<long long>(run.keyframes));
  if (run.lost > 0)
    std::printf("lost frames: %lld of %lld (%.1f%%), %.3f s in all; the longest run %lld frames (%.3f s) from t = %.3f s\n",
                static_cast<long long>(run.lost), static_cast<long long>(run.frames),
                100.0 * static_cast<double>(run.lost) / static_cast<double>(run.frames), run.lost_seconds,
                static_cast<long long>(run.longest_lost_run), run.longest_lost_seconds, run.longest_lost_start);
  if (run.skipped > 0)
    std::printf("skipped %lld bad frames (missing or undecodable images; see the warnings)\n",
                static_cast<long long>(run.skipped));
  std::printf("engine time per frame: mean %.2f ms (%.0f fps), median %.2f ms (upload, undistortion, pyramid, "
              "tracking)\n",
              run.engine_ms / std::max<int64_t>(run.frames, 1), 1000.0 * static_cast<double>(run.frames) / run.engine_ms,
              median);
  if (run.has_lean && run.attitude_unobserved > 0)
    std::printf("the body's attitude was not observed on %lld frame(s) (the car had not yet moved: it holds at the "
                "mounting given)\n",
                static_cast<long long>(run.attitude_unobserved));
  if (run.mounting_changes > 0)
    std::printf("the camera's mounting changed %lld time(s) while tracking (see the warnings)\n",
                static_cast<long long>(run.mounting_changes));
  if (run.has_lean) {
    const planarvo_line_fit &r = run.lean.roll_per_yaw_rate, &p = run.lean.pitch_per_acceleration;
    std::printf("body lean (local plane), fitted over %d frames: roll %.4f +- %.4f deg per deg/s of yaw rate (R^2 "
                "%.2f, offset %.3f deg); pitch %.3f +- %.3f deg per m/s^2 of acceleration (R^2 %.2f, offset %.3f deg)\n",
                r.samples, r.slope, r.slope_sigma, r.r2, r.offset / kDeg, p.slope / kDeg, p.slope_sigma / kDeg, p.r2,
                p.offset / kDeg);
  }
  if (!run.has_accuracy) return;
  const planarvo_motion_accuracy& a = run.accuracy;
  std::printf("accuracy against ground truth over %d intervals (all of them, degraded and lost included), %.3f m "
              "travelled:\n",
              a.intervals, a.distance);
  std::printf("  velocity slope (fit of estimated vs true)   linear %.4f   angular %.4f\n", a.slope_linear,
              a.slope_angular);
  std::printf("  per-frame translation error                 RMS %.4f mm   max %.4f mm   gross (> 1 mm) %d\n",
              a.rms_translation * 1e3, a.max_translation * 1e3, a.gross_errors);
  std::printf("  per-frame rotation error                    RMS %.4f deg\n", a.rms_rotation / kDeg);
  std::printf("  end point                                   %.2f mm (%.3f%% of distance), heading %.3f deg\n",
              a.endpoint_error * 1e3, 100 * a.endpoint_drift, a.endpoint_heading / kDeg);
  std::printf("  by the status of the interval's last frame (a lost interval's motion is the tracker's prediction):\n");
  const char* names[3] = {"ok intervals", "degraded intervals", "lost intervals"};
  for (int g = 0; g < 3; ++g) {
    const planarvo_motion_accuracy& b = run.by_status[g];
    if (b.intervals == 0) continue;
    std::printf("    %-18s %6d   translation RMS %.4f mm   max %.4f mm   rotation RMS %.4f deg\n", names[g],
                b.intervals, b.rms_translation * 1e3, b.max_translation * 1e3, b.rms_rotation / kDeg);
  }
}

namespace {

// The options of `planarvo track`.
std::vector<OptionSpec> track_options() {
  std::vector<OptionSpec> specs = {
      {"extrinsics", "FILE", "camera extrinsics YAML", "DATASET/extrinsics.yaml"},
      {"output", "FILE", "write the trajectory (TUM) to FILE (also -o)", ""},
      {"stats", "FILE", "write per-frame statistics (CSV) to FILE", ""},
      {"motions-out", "FILE", "write the tracked frame-to-frame motions, with the data set's odometry and direction "
                              "labels, as motion pairs (CSV) for calibrate --motions", ""},
      {"levels", "N", "pyramid levels", "4"},
      {"finest-level", "N", "finest pyramid level tracked (0 = full resolution)",
       "the coarsest at least 320 px wide (one pixel in four), then the level below it subsampled "
       "(--level0-subsample)"},
      {"max-iterations", "N", "cap on alignment steps per level", "per-level defaults"},
      {"level0-subsample", "B", "align the finest level (level 0 at 640x480) on one pixel per BxB block, joined with "
                                "the level above (1: every pixel; the default 3 takes about 1.4x the time of stopping "
                                "at half resolution for 0.6-0.9 of its RMS error; 1 takes about 2.5x)",
       "3 with the automatic finest level, else 1"},
      {"video", "FILE", "a video file standing in for images/ and frames.txt", ""},
      roi_option("camera.yaml's region_of_interest, else the whole image"),
      readout_option(),
      {"skip-bad-frames", "", "a missing or undecodable image is a gap (a warning, a \"skipped\" statistics row, "
                              "counted in the summary) instead of an error", ""},
      {"max-lost", "PERCENT", "exit 1 (after writing every output) when more than this share of the frames was "
                              "lost", "5"},
      {"flat-field", "FILE", "a known flat field instead of learning the light fixed to the camera: the camera's "
                             "relative brightness per (distorted) pixel, brightest = 1, an 8- or 16-bit grey image "
                             "of the camera's size (as DSO's vignette.png; --save-flat-field writes one)", ""},
      {"save-flat-field", "FILE", "after tracking, write the photometric model in use (learnt, or --flat-field's) as "
                                  "a 16-bit flat-field PNG for --flat-field (a warning when none was learnt)", ""},
      force_option(),
      {"local-plane", "", "estimate the body's roll and pitch relative to the local ground plane with every frame's "
                          "motion (a car whose body leans in turns and pitches over bumps; the extrinsics are the "
                          "camera's mounting on the body at rest)", "off: a rigid body"},
      {"plane-prior", "DEG", "with --local-plane: the standard deviation of the prior that holds the attitude at the "
                             "mounting where the images do not say otherwise", "0.5"},
      {"plane-out", "FILE", "with --local-plane: write the body's attitude per frame (t roll pitch sigma_roll "
                            "sigma_pitch, radians) to FILE", ""},
      {"mounting-change", "MODE", "with --local-plane: what a change of the camera's mounting (a step in the body's "
                                  "attitude that persists, unlike its lean in turns and over bumps) does, besides a "
                                  "warning: recalibrate (track on with the mounting changed by it: the camera turned "
                                  "about its centre, its height kept), report (keep the extrinsics given) or ignore "
                                  "(not watched)", "recalibrate"},
      {"mounting-step", "DEG", "with --local-plane: the smallest change of the mounting reported", "1"},
      {"mounting-out", "FILE", "with --local-plane: write the camera's mounting as the drive ended (extrinsics YAML: "
                               "the last change found, or the extrinsics given)", ""},
      {"quiet", "", "no progress bar", ""},
      {"help", "", "show this help", ""}};
  for (auto& b : bag_options()) specs.push_back(b);
  for (auto& d : device_options()) specs.push_back(d);
  return specs;
}

// The tracker's options from the command line; o.flat_field points into *flat_field.
planarvo_tracker_options tracker_options_from(const Args& args, std::string* flat_field) {
  planarvo_tracker_options o;
  planarvo_tracker_options_init(&o);
  o.levels = args.get_int_in("levels", o.levels, 1, 8);
  o.accept_unusual_extrinsics = args.has("force") ? 1 : 0;
  if (args.has("finest-level")) o.finest_level = args.get_int_in("finest-level", 0, 0, o.levels - 1);
  o.max_iterations = args.get_int_in("max-iterations", 0, 1, 1000);
  o.level0_subsample = args.get_int_in("level0-subsample", 0, 1, 8);
  o.local_plane = args.has("local-plane") ? 1 : 0;
  for (const char* name : {"plane-out", "plane-prior", "mounting-change", "mounting-step", "mounting-out"})
    if (args.has(name) && !o.local_plane)
      throw UsageError(std::string("--") + name +
                       " needs --local-plane: without it the body is taken as rigid and the camera's attitude to the "
                       "ground is not measured");
  if (args.has("mounting-change")) {
    const std::string mode = args.get("mounting-change");
    if (mode == "recalibrate") o.on_mounting_change = PLANARVO_MOUNTING_RECALIBRATE;
    else if (mode == "report") o.on_mounting_change = PLANARVO_MOUNTING_REPORT;
    else if (mode == "ignore") o.on_mounting_change = PLANARVO_MOUNTING_IGNORE;
    else throw UsageError("--mounting-change must be recalibrate, report or ignore, not " + mode);
  }
  if (args.has("mounting-step")) {
    const double step = args.get_double("mounting-step", 1.0);
    if (!(step > 0.0 && step <= 45.0)) throw UsageError("--mounting-step must be a positive number of degrees (up to 45)");
    o.mounting_min_step = step * kDeg;
  }
  if (args.has("plane-prior")) {
    const double sigma = args.get_double("plane-prior", 1.0);
    if (!(sigma > 0.0 && sigma <= 90.0)) throw UsageError("--plane-prior must be a positive number of degrees (up to 90)");
    o.local_plane_prior_sigma = sigma * kDeg;
  }
  *flat_field = args.get("flat-field");
  o.flat_field = flat_field->empty() ? nullptr : flat_field->c_str();
  return o;
}

}  // namespace

int cmd_track(int argc, char** argv) {
  const std::vector<OptionSpec> specs = track_options();
  Args args(specs, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo track DATASET [--extrinsics FILE] [-o trajectory.txt] [--stats stats.csv]\n"
                "       planarvo track BAG --extrinsics FILE [--image-topic T] [--camera-info-topic T | --camera FILE]\n"
                "                          [--odom-topic T] [--groundtruth-topic T] [-o trajectory.txt]\n\n"
                "Dense planar visual odometry over a data set folder, a ROS 1 bag or an MCAP file (ROS 2): prints\n"
                "a summary, and the accuracy against the ground truth when there is one.\n\n%s",
                format_options(specs).c_str());
    return kExitOk;
  }
  args.expect_positionals(1, "DATASET, the data set folder or a bag");
  const std::string dir = args.positionals()[0];
  // The options first: a usage error is reported before any file is read.
  args.expect_output_files({"output", "stats", "motions-out", "save-flat-field", "plane-out", "mounting-out"});
  std::string flat_field;  // outlives o
  const planarvo_tracker_options o = tracker_options_from(args, &flat_field);
  const std::optional<planarvo_region> roi = parse_roi(args);  // before any file is read
  const std::optional<double> readout = parse_readout(args);
  const double max_lost = args.get_double("max-lost", 5.0);
  if (!(max_lost >= 0.0 && max_lost <= 100.0))
    throw UsageError("--max-lost must be a percentage within 0..100, not " + args.get("max-lost"));
  const planarvo_extrinsics e = extrinsics_for(args, dir);
  ContextPtr ctx = make_context(args);
  Progress progress(!args.has("quiet"));
  DatasetPtr ds = open_dataset(dir, args, false, &progress, args.has("skip-bad-frames"));
  apply_roi(roi, ds.get());
  apply_readout(readout, ds.get());
  const TrackRun run = track_dataset(ctx.get(), ds.get(), e, o, {args.get("output"), args.get("stats"), args.get("motions-out"), args.has("skip-bad-frames"), args.get("save-flat-field"), args.get("plane-out"), args.get("mounting-out")}, &progress);
  progress.finish();
  std::printf("tracked %s on %s\n", dir.c_str(), device_name(ctx.get()).c_str());
  print_track_run(run);
  if (run.lost == run.frames - 1 && run.frames > 1) {
    std::fprintf(stderr, "planarvo track: tracking was lost on every frame\n");
    return kExitFailed;
  }
  const double lost_percent = run.frames > 0 ? 100.0 * static_cast<double>(run.lost) / static_cast<double>(run.frames) : 0.0;
  if (lost_percent > max_lost) {
    std::fprintf(stderr,
                 "planarvo track: %lld of %lld frames (%.1f%%) were lost, more than --max-lost %g%%; every output asked "
                 "for is written, with the tracker's predictions over the lost frames\n",
                 static_cast<long long>(run.lost), static_cast<long long>(run.frames), lost_percent, max_lost);
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace planarvo::cli
