// `planarvo posegraph` and `planarvo calibrate`: graph optimisation, no OpenCL device.
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "common.h"
#include "heap.h"

namespace planarvo::cli {
namespace {

constexpr double kDeg = M_PI / 180.0;

void print_line(void*, const char* line) { std::printf("  %s\n", line); }

// "a,b,c" with up to 6 significant digits, for the help's defaults.
std::string join(std::initializer_list<double> v) {
  std::string s;
  char buf[32];
  for (double x : v) {
    std::snprintf(buf, sizeof buf, "%.6g", x);
    s += (s.empty() ? "" : ",") + std::string(buf);
  }
  return s;
}

// --sensor-sigma / --odometry-sigma REL,FLOOR,THETA_DEG into the options' three fields.
void set_sigmas(const Args& args, const std::string& name, double* relative, double* floor, double* theta) {
  if (!args.has(name)) return;
  const auto v = args.get_doubles(name, 3);
  if (!(v[0] >= 0 && v[1] >= 0 && v[2] > 0 && (v[0] > 0 || v[1] > 0)))
    throw UsageError("--" + name + " REL,FLOOR,THETA_DEG: REL and FLOOR >= 0, not both 0, and THETA_DEG > 0");
  *relative = v[0];
  *floor = v[1];
  *theta = v[2] * kDeg;
}


// The options of `planarvo calibrate`, both forms (the defaults shown are o's).
std::vector<OptionSpec> calibrate_options(const planarvo_calibration_options& o) {
  std::vector<OptionSpec> specs = {
      {"motions", "FILE.csv", "calibrate from motion pairs (interval_s, [odo_dx, odo_dy, odo_dtheta,] sensor_dx, "
                              "sensor_dy, sensor_dtheta[, direction]) instead of a data set", ""},
      {"frames", "N", "DATASET: frames for roll and pitch, counted from the first that moves", "until 12 keyframes"},
      {"initial-extrinsics", "FILE", "DATASET: start from these extrinsics (YAML)", "looking straight down"},
      {"video", "FILE", "DATASET: a video file standing in for images/ and frames.txt", ""},
      roi_option("DATASET: camera.yaml's region_of_interest, else the whole image"),
      {"readout-time", "SECONDS|estimate", "DATASET: the rolling shutter's readout (first row's read to last row's; "
                                          "0: a global shutter), overriding camera.yaml's; estimate: from the drive",
       "camera.yaml's, else 0"},
      {"quiet", "", "no progress bar", ""},
      {"method", "KIND", "odometry | nonholonomic", "odometry"},
      {"fix-scale", "", "a metric sensor (e.g. a laser scan matcher): scale 1, z written as 0", ""},
      {"height", "METRES", "the camera height is known: hold the scale at it", ""},
      force_option(),
      {"initial", "x,y,scale,yaw", "start here (metres, degrees) instead of the built-in initialisation", ""},
      {"velocity-form", "", "nonholonomic: the paper's velocity form instead of the exact arc form", ""},
      {"sensor-sigma", "REL,FLOOR,THETA_DEG", "noise of the sensor's motions: relative part (per unit of travel and "
                                              "per radian), translation floor (sensor units), rotation floor (deg)",
       join({o.sensor_sigma_relative, o.sensor_sigma_floor, o.sensor_sigma_theta / kDeg})},
      {"odometry-sigma", "REL,FLOOR,THETA_DEG", "noise of the odometry's motions, as --sensor-sigma (floor in metres)",
       join({o.odometry_sigma_relative, o.odometry_sigma_floor, o.odometry_sigma_theta / kDeg})},
      {"loss", "KIND", "robust loss of the first solve: none | huber | cauchy | tukey", "cauchy"},
      {"loss-scale", "SIGMAS", "where the loss starts, in standard deviations", join({o.loss_scale})},
      {"gate-sigma", "SIGMAS", "drop motions whose residual exceeds this many standard deviations; 0: no gating",
       join({o.gate_sigma})},
      {"output", "FILE", "write the extrinsics YAML to FILE (also -o)", ""},
      {"verbose", "", "print the solver's iteration table", ""},
      {"help", "", "show this help", ""}};
  for (auto& b : bag_options()) specs.push_back(b);
  for (auto& d : device_options()) specs.push_back(d);
  return specs;
}

void print_calibrate_help(const std::vector<OptionSpec>& specs) {

    std::printf("usage: planarvo calibrate DATASET [--method odometry|nonholonomic] [--height METRES] [--frames N]\n"
                "                          [--initial-extrinsics FILE] -o extrinsics.yaml\n"
                "       planarvo calibrate BAG --odom-topic T [--image-topic T] [--camera-info-topic T | --camera FILE]\n"
                "                          -o extrinsics.yaml\n"
                "       planarvo calibrate --motions FILE.csv [--method odometry|nonholonomic] [--fix-scale | "
                "--height H] [-o extrinsics.yaml]\n\n"
                "Calibrates the camera's pose on the robot. From a data set: roll and pitch from the images, then\n"
                "x, y, height and yaw against wheel odometry (odometry.txt), or with --method nonholonomic from the\n"
                "nonholonomic constraint and direction labels (direction.txt) with the height given. From motion\n"
                "pairs: x, y, yaw and the camera height only. Exit code 1 when the data cannot determine the answer\n"
                "(it says why; no file is written), 2 when an input the method needs is missing.\n\n%s",
                format_options(specs).c_str());
}

// The graph calibration's options from the command line (both forms): the method, the scale held
// (a metric sensor, or a camera height), the start, the noise model, the robust loss and the gate.
// Returns whether the pairs' sensor is metric (--fix-scale).
bool read_graph_options(const Args& args, planarvo_calibration_options* out) {
  planarvo_calibration_options& o = *out;
  const std::string method = args.get("method", "odometry");
  if (method == "odometry") o.method = PLANARVO_CALIBRATE_ODOMETRY;
  else if (method == "nonholonomic") o.method = PLANARVO_CALIBRATE_NONHOLONOMIC;
  else throw UsageError("--method must be odometry or nonholonomic, not \"" + method + "\"");
  if (args.has("fix-scale") && args.has("height")) throw UsageError("give --fix-scale or --height, not both");
  const bool metric = args.has("fix-scale");
  if (metric) {
    o.fix_scale = 1;
    o.fixed_scale = 1.0;
  } else if (args.has("height")) {
    o.fix_scale = 1;
    o.fixed_scale = args.get_double("height", 0);
    if (!(o.fixed_scale > 0)) throw UsageError("--height must be positive");
  } else if (o.method == PLANARVO_CALIBRATE_NONHOLONOMIC) {
    throw UsageError("the nonholonomic method cannot estimate the scale: give --fix-scale (a metric sensor) or "
                     "--height H (the camera height)");
  }
  if (args.has("initial")) {
    const auto v = args.get_doubles("initial", 4);
    o.has_initial = 1;
    o.initial[0] = v[0];
    o.initial[1] = v[1];
    o.initial[2] = v[2];
    o.initial[3] = v[3] * kDeg;
  }
  o.velocity_form = args.has("velocity-form") ? 1 : 0;
  set_sigmas(args, "sensor-sigma", &o.sensor_sigma_relative, &o.sensor_sigma_floor, &o.sensor_sigma_theta);
  set_sigmas(args, "odometry-sigma", &o.odometry_sigma_relative, &o.odometry_sigma_floor, &o.odometry_sigma_theta);
  const std::string loss = args.get("loss", "cauchy");
  if (loss == "none") o.loss = PLANARVO_ROBUST_LOSS_NONE;
  else if (loss == "huber") o.loss = PLANARVO_ROBUST_LOSS_HUBER;
  else if (loss == "cauchy") o.loss = PLANARVO_ROBUST_LOSS_CAUCHY;
  else if (loss == "tukey") o.loss = PLANARVO_ROBUST_LOSS_TUKEY;
  else throw UsageError("--loss must be none, huber, cauchy or tukey, not \"" + loss + "\"");
  o.loss_scale = args.get_double("loss-scale", o.loss_scale);
  if (!(o.loss_scale > 0)) throw UsageError("--loss-scale must be positive");
  o.gate_sigma = args.get_double("gate-sigma", o.gate_sigma);
  if (!(o.gate_sigma >= 0)) throw UsageError("--gate-sigma must be >= 0");
  if (args.has("verbose")) o.log = &print_line;
  return metric;
}

// `planarvo calibrate --motions FILE.csv`: the graph calibration of motion pairs.
int calibrate_motions(const Args& args, const planarvo_calibration_options& o, bool metric) {
  const std::string method = args.get("method", "odometry");
  const std::string path = args.get("motions");
  size_t n = 0;
  check(planarvo_motion_pairs_load(path.c_str(), nullptr, 0, &n));
  std::vector<planarvo_motion_pair> pairs(n);
  for (planarvo_motion_pair& p : pairs) planarvo_motion_pair_init(&p);
  check(planarvo_motion_pairs_load(path.c_str(), pairs.data(), n, &n));
  planarvo_calibration_result r{};
  r.struct_size = sizeof r;
  const planarvo_status st = planarvo_calibrate(pairs.data(), n, &o, &r);
  if (st != PLANARVO_OK && st != PLANARVO_ERROR_FAILED) check(st);

  static const char* names[4] = {"x", "y", "scale", "yaw"};
  std::printf("%s calibration from %zu motion pairs (%d rejected as gross errors)\n", method.c_str(), n, r.outliers);
  for (int i = 0; i < 4; ++i) {
    const double sd = std::sqrt(std::max(0.0, r.covariance[i * 5]));
    const bool angle = i == 3;
    const double k = angle ? 1 / kDeg : 1e3;
    const char* unit = angle ? "deg" : "mm";
    if (i == 2 && metric) continue;
    if (!r.estimated[i]) {
      std::printf("  %-5s %10.3f %-3s  (held)\n", names[i], r.value[i] * k, unit);
      continue;
    }
    std::printf("  %-5s %10.3f %-3s  +- %.3f%s\n", names[i], r.value[i] * k, unit, sd * k,
                r.observable[i] ? "" : "  UNOBSERVABLE");
  }
  std::printf("solver: %d iterations over all solves, %.3f s; the final solve: %d iterations, %s\n",
              r.total_iterations, r.total_seconds, r.summary.iterations, r.summary.termination);
  std::printf("variance factor %.3g (included in the +-)\n", r.variance_factor);
  if (r.ambiguous) std::printf("ambiguous: (-x, -y, yaw + 180 deg) fits equally well\n");
  if (r.unobservable_reason[0]) std::printf("%s\n", r.unobservable_reason);

  const std::string out = args.get("output");
  if (!out.empty() && !r.ok) std::printf("%s not written: the calibration is not determined\n", out.c_str());
  if (!out.empty() && r.ok) {
    const std::string notes = std::to_string(n) + " motion pairs from " + path;
    check(planarvo_calibration_save(out.c_str(), &r, o.method, metric ? 1 : 0, notes.c_str()));
    std::printf("wrote %s\n", out.c_str());
  }
  if (st == PLANARVO_ERROR_FAILED) {
    std::fprintf(stderr, "planarvo calibrate: %s\n", planarvo_last_error());
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace

int cmd_posegraph(int argc, char** argv) {
  const std::vector<OptionSpec> specs = {
      {"output", "FILE", "write the optimised graph (g2o) to FILE (also -o)", ""},
      {"max-iterations", "N", "iteration cap", "100"},
      {"init", "KIND", "none | rotation (orientations first, then positions)", "none"},
      {"verbose", "", "print the iteration table", ""},
      {"help", "", "show this help", ""}};
  Args args(specs, argc, argv, 1);
  if (args.has("help")) {
    std::printf("usage: planarvo posegraph IN.g2o [-o OUT.g2o] [--init rotation] [--verbose]\n\n"
                "Optimises a 2-D pose graph in g2o's format (VERTEX_SE2, EDGE_SE2; the first vertex held\n"
                "fixed) with planarvo's sparse Levenberg-Marquardt solver on CHOLMOD.\n\n%s",
                format_options(specs).c_str());
    return kExitOk;
  }
  args.expect_positionals(1, "IN.g2o, the pose graph to optimise");
  prepare_heap();  // a short, allocation-bound run (heap.h)
  planarvo_posegraph_options o;
  planarvo_posegraph_options_init(&o);
  o.max_iterations = args.get_int_in("max-iterations", o.max_iterations, 1, 1000000);
  const std::string init = args.get("init", "none");
  if (init == "rotation") o.init = PLANARVO_POSEGRAPH_INIT_ROTATION_FIRST;
  else if (init != "none") throw UsageError("--init must be none or rotation");
  if (args.has("verbose")) o.log = &print_line;
  planarvo_solver_summary s{};
  s.struct_size = sizeof s;
  args.expect_output_files({"output"});
  const std::string out = args.get("output");
  const planarvo_status st = planarvo_posegraph_optimize(args.positionals()[0].c_str(), out.empty() ? nullptr : out.c_str(), &o, &s);
  if (st != PLANARVO_OK && st != PLANARVO_ERROR_FAILED) check(st);
  std::printf("%s: chi2 %.6f -> %.6f in %d iterations (%d factorisations), %.3f s\n",
              args.positionals()[0].c_str(), s.initial_chi2, s.final_chi2, s.iterations, s.factorizations, s.seconds);
  std::printf("termination: %s\n", s.termination);
  if (!out.empty()) std::printf("wrote %s\n", out.c_str());
  if (st == PLANARVO_ERROR_FAILED) {
    std::fprintf(stderr, "planarvo posegraph: %s\n", planarvo_last_error());
    return kExitFailed;
  }
  return kExitOk;
}

int cmd_calibrate(int argc, char** argv) {
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  const std::vector<OptionSpec> specs = calibrate_options(o);
  Args args(specs, argc, argv, 1);
  const bool dataset = !args.positionals().empty();
  if (args.has("help")) {
    print_calibrate_help(specs);
    return kExitOk;
  }
  if (!dataset && !args.has("motions")) throw UsageError("missing DATASET, the data set folder (or --motions FILE.csv)");
  if (dataset && args.has("motions")) throw UsageError("give a DATASET or --motions FILE.csv, not both");
  if (args.positionals().size() > 1) throw UsageError("unexpected argument " + args.positionals()[1]);
  args.expect_output_files({"output"});  // both forms: before any work
  const bool metric = read_graph_options(args, &o);
  if (dataset) return cmd_calibrate_dataset(args, o);
  return calibrate_motions(args, o, metric);
}

}  // namespace planarvo::cli
