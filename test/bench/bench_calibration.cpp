// The graph calibrations (paper sec. 5.2) measured. Prints:
//   (a) the Censi laser data (shared/data/real/censi2011): lstraight, l90, lmov by the odometry
//       method (scale fixed at 1) and the nonholonomic method (labels from the odometry's sign),
//       with standard deviations, gated outliers, iterations and time; the lmov archive beside;
//   (b) the arc and the velocity forms of the nonholonomic residual on noise-free synthetic
//       motions at several frame intervals and speeds: error in x and yaw;
//   (c) the direction prior's floor: y with labels 0 that are not quite in place, and the
//       interval that labels ±1 alone leave;
//   (d) the odometry method on calibration graphs of 1k, 10k, 100k poses: time, iterations,
//       error against the truth in units of the reported σ.
// Usage: bench_calibration [--only censi|forms|prior|scaling] [--sizes N,N,...]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "graph/calibration/calibration.h"
#include "io/motions.h"
#include "../unit/graph_calibration_sim.h"

using namespace planarvo;
using namespace planarvo::graph;

namespace {

const std::array<double, 4> kTruth = {0.2441, -0.0185, 0.1787, -9.2 * M_PI / 180};
constexpr double kDeg = 180.0 / M_PI;

std::vector<MotionSample> censi(const std::string& name) {
  const auto pairs = io::read_motion_pairs(std::string(PLANARVO_SHARED_DIR) +
                                           "/data/real/censi2011/" + name + "_motions.csv");
  std::vector<MotionSample> samples;
  for (const io::MotionPair& p : pairs.pairs) {
    MotionSample s;
    s.interval = p.interval;
    s.sensor = p.sensor;
    s.odometry = p.odometry;
    s.direction = p.direction;
    samples.push_back(s);
  }
  return samples;
}

double sd(const CalibrationResult& r, int k) { return std::sqrt(r.covariance(k, k)); }

void censi_table() {
  std::printf("(a) Censi et al. laser scanner on a differential drive, scale fixed at 1 (metric)\n");
  std::printf("    odometry: against wheel odometry; nonholonomic: labels from the odometry's sign only\n");
  std::printf("%-10s %-13s %17s %17s %19s %5s %6s %8s %5s %4s %3s\n", "data", "method", "x [mm]",
              "y [mm]", "yaw [deg]", "rows", "gated", "var.fac", "iters", "ms", "ok");
  for (const char* name : {"lstraight", "l90", "lmov"}) {
    const auto samples = censi(name);
    for (auto method : {CalibrationMethod::Odometry, CalibrationMethod::Nonholonomic}) {
      CalibrationOptions o;
      o.method = method;
      o.fix_scale = true;
      const CalibrationResult r = calibrate(samples, o);
      std::printf("%-10s %-13s %8.3f ± %6.3f %8.3f ± %6.3f %9.4f ± %6.4f %5zu %6d %8.1f %5d %4.0f %3s\n", name,
                  method == CalibrationMethod::Odometry ? "odometry" : "nonholonomic",
                  1e3 * r.value[0], 1e3 * sd(r, 0), 1e3 * r.value[1], 1e3 * sd(r, 1),
                  kDeg * r.value[3], kDeg * sd(r, 3), samples.size(), r.outliers,
                  r.variance_factor, r.total_iterations, 1e3 * r.total_time_s,
                  r.ok() ? "yes" : "no");
    }
  }
  std::printf("%-10s %-13s %8.3f ± %6.3f %8.3f ± %6.3f %9.4f ± %6.4f   (lmov_reference_result.json)\n",
              "lmov", "archive", -5.87095, 1e3 * std::sqrt(1.59008e-06), -38.7078,
              1e3 * std::sqrt(4.53146e-07), kDeg * -1.86026, kDeg * std::sqrt(0.000435694));
  std::printf("\n");
}

void forms_table() {
  std::printf("(b) nonholonomic residual, arc vs velocity form: noise-free motions, drives of forwards/backwards\n"
              "    arcs with |omega| <= 0.8 rad/s, straight and turning in place; RMS error over 4 seeds\n");
  std::printf("%8s %9s %12s | %11s %11s | %11s %11s\n", "dt [s]", "v [m/s]", "max w*dt", "arc x [mm]",
              "arc yaw[°]", "vel x [mm]", "vel yaw[°]");
  for (double dt : {1.0, 0.5, 0.2, 0.1, 1.0 / 30}) {
    for (double vmax : {0.2, 0.4, 1.0}) {
      double e[4] = {0, 0, 0, 0};
      for (unsigned seed = 1; seed <= 4; ++seed) {
        test::CalibrationSim sim;
        sim.odometry = false;
        sim.dt = dt;
        sim.speed_min = 0.25 * vmax;
        sim.speed_max = vmax;
        sim.seed = seed;
        const auto samples = test::simulate_motions(kTruth, sim).samples;
        CalibrationOptions o;
        o.method = CalibrationMethod::Nonholonomic;
        o.fixed_scale = kTruth[2];
        for (int f = 0; f < 2; ++f) {
          o.nonholonomic_form = f == 0 ? CalibrationOptions::NonholonomicForm::Arc
                                       : CalibrationOptions::NonholonomicForm::Velocity;
          const CalibrationResult r = calibrate(samples, o);
          e[2 * f] += 0.25 * std::pow(r.value[0] - kTruth[0], 2);
          e[2 * f + 1] += 0.25 * std::pow(wrap_angle(r.value[3] - kTruth[3]), 2);
        }
      }
      std::printf("%8.3f %4.2f-%4.2f %12.3f | %11.2e %11.2e | %11.3f %11.3f\n", dt, 0.25 * vmax, vmax,
                  0.8 * dt, 1e3 * std::sqrt(e[0]), kDeg * std::sqrt(e[1]), 1e3 * std::sqrt(e[2]),
                  kDeg * std::sqrt(e[3]));
    }
  }
  std::printf("\n");
}

void prior_table() {
  std::printf("(c) direction prior (eq. 31) floor, x and yaw from the arc form, noise-free unless stated\n");
  CalibrationOptions o;
  o.method = CalibrationMethod::Nonholonomic;
  o.fixed_scale = kTruth[2];
  std::printf("    labels 0 on intervals turned 'in place' at a residual forward speed v0 (|omega| 0.24-0.8 rad/s, dt 1 s):\n");
  std::printf("%14s %14s %14s\n", "v0 [m/s]", "y error [mm]", "sigma_y [mm]");
  for (double v0 : {0.0, 1e-4, 1e-3, 1e-2}) {
    test::CalibrationSim sim;
    sim.odometry = false;
    sim.in_place_speed = v0;
    const CalibrationResult r = calibrate(test::simulate_motions(kTruth, sim).samples, o);
    std::printf("%14.0e %14.3g %14.3g\n", v0, 1e3 * (r.value[1] - kTruth[1]), 1e3 * sd(r, 1));
  }
  std::printf("    labels 0 with sensor noise (3 mm, 3 mrad per interval, 300 intervals, 50 turned in place), 20 seeds:\n");
  {
    double se = 0.0, ss = 0.0;
    for (unsigned seed = 1; seed <= 20; ++seed) {
      test::CalibrationSim sim;
      sim.odometry = false;
      sim.seed = seed;
      sim.sensor_sigma_t = 0.003 / kTruth[2];
      sim.sensor_sigma_theta = 0.003;
      const CalibrationResult r = calibrate(test::simulate_motions(kTruth, sim).samples, o);
      se += std::pow(r.value[1] - kTruth[1], 2) / 20;
      ss += r.covariance(1, 1) / 20;
    }
    std::printf("%14s RMS y error %.3f mm, RMS reported sigma_y %.3f mm\n", "", 1e3 * std::sqrt(se), 1e3 * std::sqrt(ss));
  }
  std::printf("    labels +1/-1 only (no 0): the interval of y they leave, by the sharpest turn (speeds 0.1-0.4 m/s,\n"
              "    dt 0.25 s, so that the tightest radius is 0.1 m / max|omega|):\n");
  std::printf("%10s %14s %12s %12s %12s %14s %5s\n", "drive", "max |omega|", "lo-y [mm]", "hi-y [mm]",
              "width [mm]", "sigma_y [mm]", "ok");
  for (auto drive : {test::Drive::Rich, test::Drive::ForwardOnly}) {
    for (double wmax : {0.3, 0.8, 2.0, 5.0, 10.0}) {
      test::CalibrationSim sim;
      sim.odometry = false;
      sim.drive = drive;
      sim.omega_max = wmax;
      sim.dt = 0.25;
      auto data = test::simulate_motions(kTruth, sim);
      for (MotionSample& s : data.samples)
        if (s.direction && *s.direction == 0) s.direction.reset();
      const CalibrationResult r = calibrate(data.samples, o);
      const double lo = r.y_interval ? (*r.y_interval)[0] - kTruth[1] : NAN;
      const double hi = r.y_interval ? (*r.y_interval)[1] - kTruth[1] : NAN;
      std::printf("%10s %14.1f %12.1f %12.1f %12.1f %14.1f %5s\n",
                  drive == test::Drive::Rich ? "fwd+bwd" : "fwd only", wmax, 1e3 * lo, 1e3 * hi,
                  1e3 * (hi - lo), 1e3 * sd(r, 1), r.ok() ? "yes" : "no");
    }
  }
  std::printf("\n");
}

void scaling_table(const std::vector<int>& sizes) {
  std::printf("(d) odometry method on calibration graphs (poses = intervals + 1), noise 3 mm / 3 mrad per\n"
              "    interval on both sensor and odometry, 1%% gross sensor errors of 1-2 dm\n");
  std::printf("%9s %9s %7s %8s %8s %7s %26s\n", "poses", "time [s]", "iters", "gated", "injected",
              "ok", "error / sigma (x y s yaw)");
  for (int n : sizes) {
    test::CalibrationSim sim;
    sim.intervals = n;
    sim.seed = 7;
    sim.sensor_sigma_t = 0.003 / kTruth[2];
    sim.sensor_sigma_theta = 0.003;
    sim.odometry_sigma_t = 0.003;
    sim.odometry_sigma_theta = 0.003;
    sim.outlier_fraction = 0.01;
    sim.outlier_size = 0.2;
    const auto data = test::simulate_motions(kTruth, sim);
    const CalibrationResult r = calibrate(data.samples, CalibrationOptions{});
    std::printf("%9d %9.2f %7d %8d %8zu %7s", n + 1, r.total_time_s, r.total_iterations, r.outliers,
                data.outliers.size(), r.ok() ? "yes" : "no");
    for (int k = 0; k < 4; ++k) {
      const double d = k == 3 ? wrap_angle(r.value[3] - kTruth[3]) : r.value[static_cast<size_t>(k)] - kTruth[static_cast<size_t>(k)];
      std::printf(" %6.2f", d / sd(r, k));
    }
    std::printf("\n");
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  std::string only;
  std::vector<int> sizes = {1000, 10000, 100000};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else if (a == "--sizes" && i + 1 < argc) {
      sizes.clear();
      std::stringstream ss(argv[++i]);
      std::string item;
      while (std::getline(ss, item, ',')) sizes.push_back(std::atoi(item.c_str()));
    } else {
      std::fprintf(stderr, "usage: bench_calibration [--only censi|forms|prior|scaling] [--sizes N,N,...]\n");
      return 2;
    }
  }
  if (only.empty() || only == "censi") censi_table();
  if (only.empty() || only == "forms") forms_table();
  if (only.empty() || only == "prior") prior_table();
  if (only.empty() || only == "scaling") scaling_table(sizes);
  return 0;
}
