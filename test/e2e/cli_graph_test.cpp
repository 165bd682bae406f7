// `planarvo posegraph` and `planarvo calibrate --motions` as a user runs them, compared value by
// value with the same computation through the C API (planarvo_posegraph_optimize,
// planarvo_motion_pairs_load + planarvo_calibrate): the printed chi^2, iterations, estimates, sigmas
// and totals, and the written graph and extrinsics YAML; and with independent references: the
// graphs' reference optima and the chi^2 of the written file recomputed in the test, the archive's
// calibration of Censi et al.'s lmov data. Exit codes and messages for bad input.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/printed_values.h"
#include "common/test_util.h"
#include "io/formats.h"
#include "planarvo/planarvo.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using test::expect_printed;
using test::numbers_after;
using test::run_cli;
using test::ScratchDir;

constexpr double kDeg = M_PI / 180.0;

std::string read(const fs::path& p) { return test::read_file(p); }

fs::path posegraph(const std::string& name) { return test::shared_dir() / "data/posegraphs" / name; }

// "IN: chi2 A -> B in N iterations (F factorisations), T s" and "termination: ..." against the
// C API's summary of the same solve.
void expect_printed_summary(const std::string& output, const planarvo_solver_summary& s) {
  const std::vector<double> v = numbers_after(output, ": chi2 ");
  ASSERT_EQ(v.size(), 5u) << output;
  expect_printed(v[0], s.initial_chi2, 6, "initial chi2");
  expect_printed(v[1], s.final_chi2, 6, "final chi2");
  EXPECT_EQ(v[2], s.iterations);
  EXPECT_EQ(v[3], s.factorizations);
  EXPECT_GE(v[4], 0.0);
  EXPECT_EQ(test::line_with(output, "termination: "), std::string("termination: ") + s.termination);
}

// Ring from the file's poses and intel after rotation-first initialisation: the tool prints and
// writes what the C API computes, the reference optimum, and the chi^2 it prints is that of the
// graph it wrote.
TEST(CliPosegraph, PrintsAndWritesWhatTheCApiComputes) {
  ScratchDir d;
  struct Case {
    const char* file;
    bool rotation_first;
    double optimum;
  };
  for (const Case& c : {Case{"ring.g2o", false, 11.1631}, Case{"intel.g2o", true, 546.461}}) {
    SCOPED_TRACE(c.file);
    const std::string in = posegraph(c.file).string();
    const fs::path cli_out = d / (std::string("cli_") + c.file), api_out = d / (std::string("api_") + c.file);
    const std::string init = c.rotation_first ? " --init rotation" : "";
    const auto r = run_cli("posegraph " + in + " -o " + cli_out.string() + init);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    planarvo_posegraph_options o;
    planarvo_posegraph_options_init(&o);
    o.init = c.rotation_first ? PLANARVO_POSEGRAPH_INIT_ROTATION_FIRST : PLANARVO_POSEGRAPH_INIT_NONE;
    planarvo_solver_summary s{};
    s.struct_size = sizeof s;
    ASSERT_EQ(planarvo_posegraph_optimize(in.c_str(), api_out.string().c_str(), &o, &s), PLANARVO_OK)
        << planarvo_last_error();
    expect_printed_summary(r.output, s);
    EXPECT_EQ(read(cli_out), read(api_out));  // the same poses, digit for digit
    EXPECT_NEAR(test::g2o_chi2(in), s.initial_chi2, 1e-9 * s.initial_chi2);
    EXPECT_NEAR(test::g2o_chi2(cli_out.string()), s.final_chi2, 1e-6 * s.final_chi2);
    EXPECT_NEAR(s.final_chi2, c.optimum, 5e-4 * c.optimum);
  }
  // The optimum optimised again: starts and ends at the chi^2 of the written file.
  const fs::path optimum = d / "cli_ring.g2o";
  const auto r = run_cli("posegraph " + optimum.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<double> v = numbers_after(r.output, ": chi2 ");
  ASSERT_EQ(v.size(), 5u) << r.output;
  expect_printed(v[0], test::g2o_chi2(optimum.string()), 6, "initial chi2");
  EXPECT_NEAR(v[1], v[0], 1e-5);
}

// Stopped by --max-iterations: exit 1, and the graph it reached written with the chi^2 it prints.
TEST(CliPosegraph, AnIterationCapIsExit1AndWritesTheGraphItReached) {
  ScratchDir d;
  const std::string in = posegraph("ring.g2o").string();
  const fs::path out = d / "capped.g2o";
  const auto r = run_cli("posegraph " + in + " --max-iterations 2 -o " + out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const std::vector<double> v = numbers_after(r.output, ": chi2 ");
  ASSERT_EQ(v.size(), 5u) << r.output;
  EXPECT_EQ(v[2], 2.0);
  ASSERT_TRUE(fs::exists(out));
  expect_printed(v[1], test::g2o_chi2(out.string()), 6, "final chi2");
  EXPECT_GT(v[1], 11.1631 * 1.01);  // short of the optimum
}

TEST(CliPosegraph, BadFileNamesTheLine) {
  ScratchDir d;
  const fs::path bad = d / "bad.g2o";
  std::ofstream(bad) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0\n";
  auto r = run_cli("posegraph " + bad.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.g2o:2"), std::string::npos) << r.output;
}

// A NaN in an edge is bad input like one in a vertex: exit 2 naming the line, no output graph.
TEST(CliPosegraph, NanInAnEdgeIsBadInputAndWritesNothing) {
  ScratchDir d;
  const fs::path bad = d / "bad.g2o", out = d / "out.g2o";
  std::ofstream(bad) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 nan 0 0 1 0 0 1 0 1\n";
  auto r = run_cli("posegraph " + bad.string() + " -o " + out.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.g2o:3"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

// Every number finite, but the edge's error at the file's poses overflows eᵀΩe (found by
// fuzz_g2o: a vertex at -6e307 m). Bad input with either initialisation, nothing written; the
// same graph with the vertex at a large but sane coordinate solves.
TEST(CliPosegraph, AnOverflowingEdgeIsBadInputAndWritesNothing) {
  ScratchDir d;
  const fs::path bad = d / "overflow.g2o", fine = d / "far.g2o", out = d / "out.g2o";
  std::ofstream(bad) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 -0.6236931e308 0 0\nEDGE_SE2 0 1 1 0 0 500 0 0 500 0 5000\n";
  std::ofstream(fine) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1e6 0 0\nEDGE_SE2 0 1 1 0 0 500 0 0 500 0 5000\n";
  for (const char* init : {"", " --init rotation"}) {
    auto r = run_cli("posegraph " + bad.string() + " -o " + out.string() + init);
    EXPECT_EQ(r.exit_code, 2) << init << r.output;
    EXPECT_FALSE(fs::exists(out)) << init;
    planarvo_solver_summary s{};
    s.struct_size = sizeof s;
    EXPECT_EQ(planarvo_posegraph_optimize(bad.string().c_str(), nullptr, nullptr, &s), PLANARVO_ERROR_INVALID_INPUT);
    r = run_cli("posegraph " + fine.string() + " -o " + out.string() + init);
    EXPECT_EQ(r.exit_code, 0) << init << r.output;
    ASSERT_TRUE(fs::exists(out)) << init;
    // The solution: vertex 1 one metre from vertex 0, as the edge says.
    std::ifstream in(out);
    std::string tag;
    int id = -1;
    double x = 0, y = 0, th = 0;
    while (in >> tag && !(tag == "VERTEX_SE2" && in >> id >> x >> y >> th && id == 1)) {
    }
    EXPECT_EQ(id, 1) << init;
    EXPECT_NEAR(x, 1.0, 1e-6) << init;
    in.close();
    fs::remove(out);
  }
}

// ---- calibrate --motions -------------------------------------------------------------------

const std::string kLmov = (test::shared_dir() / "data/real/censi2011/lmov_motions.csv").string();

struct ApiCalibration {
  planarvo_status status = PLANARVO_OK;
  size_t pairs = 0;
  planarvo_calibration_result result{};
};

ApiCalibration calibrate_api(const std::string& csv, const planarvo_calibration_options& o) {
  ApiCalibration c;
  EXPECT_EQ(planarvo_motion_pairs_load(csv.c_str(), nullptr, 0, &c.pairs), PLANARVO_OK) << planarvo_last_error();
  std::vector<planarvo_motion_pair> pairs(c.pairs);
  for (planarvo_motion_pair& p : pairs) planarvo_motion_pair_init(&p);
  EXPECT_EQ(planarvo_motion_pairs_load(csv.c_str(), pairs.data(), c.pairs, &c.pairs), PLANARVO_OK);
  c.result.struct_size = sizeof c.result;
  c.status = planarvo_calibrate(pairs.data(), c.pairs, &o, &c.result);
  return c;
}

planarvo_calibration_options metric() {
  planarvo_calibration_options o;
  planarvo_calibration_options_init(&o);
  o.fix_scale = 1;
  o.fixed_scale = 1.0;
  return o;
}

// The parameter's line ("  x        -5.890 mm  +- 0.094"), "" when none.
std::string parameter_line(const std::string& output, const std::string& name) {
  std::string label = "  " + name;
  label.resize(8, ' ');
  const std::string line = test::line_with(output, label);
  return line.rfind(label, 0) == 0 ? line : "";
}

// The printed report of a metric calibration against the C API's result of the same.
void expect_printed_calibration(const std::string& output, const ApiCalibration& c) {
  const planarvo_calibration_result& r = c.result;
  const std::vector<double> head = numbers_after(output, "calibration from ");
  ASSERT_EQ(head.size(), 2u) << output;
  EXPECT_EQ(head[0], static_cast<double>(c.pairs));
  EXPECT_EQ(head[1], r.outliers);
  const char* names[4] = {"x", "y", "scale", "yaw"};
  for (int i : {0, 1, 3}) {
    const std::string line = parameter_line(output, names[i]);
    const std::vector<double> v = test::numbers_in(line);
    const double k = i == 3 ? 1 / kDeg : 1e3, sd = std::sqrt(std::max(0.0, r.covariance[i * 5]));
    ASSERT_EQ(v.size(), std::isfinite(sd) ? 2u : 1u) << names[i] << "\n" << output;
    expect_printed(v[0], r.value[i] * k, 3, names[i]);
    if (std::isfinite(sd)) expect_printed(v[1], sd * k, 3, names[i]);
    else EXPECT_NE(line.find("+- inf"), std::string::npos) << line;
    EXPECT_EQ(line.find("UNOBSERVABLE") == std::string::npos, r.observable[i] != 0) << line;
  }
  EXPECT_EQ(parameter_line(output, "scale"), "") << output;  // a metric sensor has none
  const std::vector<double> solver = numbers_after(output, "solver: ");
  ASSERT_GE(solver.size(), 3u) << output;
  EXPECT_EQ(solver[0], r.total_iterations);
  EXPECT_EQ(solver[2], r.summary.iterations);
  const std::vector<double> vf = numbers_after(output, "variance factor ");
  ASSERT_EQ(vf.size(), 1u) << output;
  EXPECT_NEAR(vf[0], r.variance_factor, 5e-3 * r.variance_factor);  // 3 significant digits
}

// Censi et al.'s laser scan matcher against the robot's odometry: the printed report and the
// written YAML are the C API's result, and that is the archive's calibration within its sigma.
TEST(CliCalibrate, CensiLmovPrintsAndWritesWhatTheCApiComputes) {
  ScratchDir d;
  const std::string out = (d / "extrinsics.yaml").string();
  const auto r = run_cli("calibrate --motions " + kLmov + " --fix-scale -o " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ApiCalibration c = calibrate_api(kLmov, metric());
  ASSERT_EQ(c.status, PLANARVO_OK) << planarvo_last_error();
  expect_printed_calibration(r.output, c);

  const ExtrinsicsEstimate f = io::read_extrinsics_yaml(out);
  const double* v = c.result.value;
  EXPECT_NEAR(f.value.x, v[0], 1e-15);
  EXPECT_NEAR(f.value.y, v[1], 1e-15);
  EXPECT_EQ(f.value.z, 0.0);  // a metric sensor: no height
  EXPECT_EQ(f.value.roll, 0.0);
  EXPECT_EQ(f.value.pitch, 0.0);
  EXPECT_NEAR(f.value.yaw, v[3], 1e-15);
  const int map[6] = {0, 1, -1, -1, -1, 3};  // x y z roll pitch yaw <- x y scale yaw
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const double expected = map[i] < 0 || map[j] < 0 ? 0.0 : c.result.covariance[map[i] * 4 + map[j]];
      EXPECT_NEAR(f.covariance(i, j), expected, 1e-12 * std::abs(expected)) << i << "," << j;
    }
  EXPECT_EQ(f.estimated, (std::array<bool, 6>{true, true, false, false, false, true}));  // x, y, yaw

  // The archive (shared/data/real/censi2011): x -5.871 +- 1.261 mm, y -38.708 +- 0.673 mm,
  // yaw -106.585 +- 1.196 deg.
  EXPECT_NEAR(v[0], -5.871e-3, 1.261e-3);
  EXPECT_NEAR(v[1], -38.708e-3, 0.673e-3);
  EXPECT_NEAR(v[3] / kDeg, -106.585, 1.196);
}

// The noise-model options reach the solver as the C API's fields: printed estimates, rejections
// and totals equal the C API's with the same options; bad values are usage errors.
TEST(CliCalibrate, NoiseModelOptionsActAsTheCApiFields) {
  struct Case {
    const char* args;
    void (*set)(planarvo_calibration_options*);
  };
  const Case cases[] = {
      {"", [](planarvo_calibration_options*) {}},
      {" --gate-sigma 0 --loss none --sensor-sigma 0.01,0.001,0.1",
       [](planarvo_calibration_options* o) {
         o->gate_sigma = 0;
         o->loss = PLANARVO_ROBUST_LOSS_NONE;
         o->sensor_sigma_relative = 0.01;
         o->sensor_sigma_floor = 0.001;
         o->sensor_sigma_theta = 0.1 * kDeg;
       }},
      {" --loss huber --loss-scale 2 --gate-sigma 4 --odometry-sigma 0.02,0.0005,0.2",
       [](planarvo_calibration_options* o) {
         o->loss = PLANARVO_ROBUST_LOSS_HUBER;
         o->loss_scale = 2;
         o->gate_sigma = 4;
         o->odometry_sigma_relative = 0.02;
         o->odometry_sigma_floor = 0.0005;
         o->odometry_sigma_theta = 0.2 * kDeg;
       }},
  };
  std::vector<double> xs;
  for (const Case& k : cases) {
    SCOPED_TRACE(k.args);
    const auto r = run_cli("calibrate --motions " + kLmov + " --fix-scale" + k.args);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    planarvo_calibration_options o = metric();
    k.set(&o);
    const ApiCalibration c = calibrate_api(kLmov, o);
    ASSERT_EQ(c.status, PLANARVO_OK) << planarvo_last_error();
    expect_printed_calibration(r.output, c);
    xs.push_back(c.result.value[0]);
  }
  EXPECT_NE(xs[0], xs[1]);  // the options changed the answer
  EXPECT_NE(xs[0], xs[2]);
  EXPECT_EQ(run_cli("calibrate --motions " + kLmov + " --fix-scale --gate-sigma -1").exit_code, 2);
  EXPECT_EQ(run_cli("calibrate --motions " + kLmov + " --fix-scale --loss l2").exit_code, 2);
  EXPECT_EQ(run_cli("calibrate --motions " + kLmov + " --fix-scale --odometry-sigma 0,0,1").exit_code, 2);
}

// Driving straight forwards and backwards does not determine x and y: exit 1, no file, and the
// printed flags and reason are the C API's.
TEST(CliCalibrate, StraightDrivingIsUnobservableExit1AndNoFile) {
  ScratchDir d;
  const fs::path csv = d / "straight.csv";
  {
    std::ofstream o(csv);
    o << "# interval_s,odo_dx,odo_dy,odo_dtheta,sensor_dx,sensor_dy,sensor_dtheta\n";
    for (int i = 0; i < 200; ++i) {
      const double dx = (i % 40 < 20 ? 1 : -1) * 0.01;
      // The sensor at yaw 90 deg sees the forward motion as motion to its right.
      o << "0.1," << dx << ",0,0,0," << -dx << ",0\n";
    }
  }
  const std::string out = (d / "e.yaml").string();
  auto r = run_cli("calibrate --motions " + csv.string() + " --fix-scale -o " + out);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_FALSE(fs::exists(out));
  const ApiCalibration c = calibrate_api(csv.string(), metric());
  EXPECT_EQ(c.status, PLANARVO_ERROR_FAILED);
  EXPECT_EQ(c.result.observable[0], 0);
  EXPECT_EQ(c.result.observable[1], 0);
  expect_printed_calibration(r.output, c);
  const std::string reason = c.result.unobservable_reason;
  EXPECT_NE(r.output.find("\n" + reason + "\n"), std::string::npos) << r.output;  // in the report
  EXPECT_EQ(test::line_with(r.output, "planarvo calibrate: "), "planarvo calibrate: " + reason);  // and the error
}

TEST(CliCalibrate, NonholonomicNeedsAScale) {
  auto r = run_cli("calibrate --method nonholonomic --motions " + kLmov);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--height"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace planarvo
