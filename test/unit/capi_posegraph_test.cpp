// planarvo_posegraph_optimize through the C API, against independent references: the shared
// graphs' reference optima (reached by Ceres Solver and g2o, ../shared/data/posegraphs/README.md),
// and the chi^2 of the written graph recomputed here from the file with g2o's error convention
// in plain Eigen (not the solver's code). Also: no output path, the log callback, bad input.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "common/test_util.h"
#include "planarvo/planarvo.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;

struct Pose {
  double x, y, theta;
};

Eigen::Matrix3d v2t(const Pose& p) {
  Eigen::Matrix3d T;
  T << std::cos(p.theta), -std::sin(p.theta), p.x, std::sin(p.theta), std::cos(p.theta), p.y, 0, 0, 1;
  return T;
}

// chi^2 = sum e' Omega e, e = t2v(Z^-1 (X_i^-1 X_j)), over the EDGE_SE2 lines of a g2o file.
double chi2_of_file(const fs::path& path) {
  std::ifstream in(path);
  std::unordered_map<int, Pose> vertices;
  struct Edge {
    int i, j;
    Pose z;
    Eigen::Matrix3d omega;
  };
  std::vector<Edge> edges;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "VERTEX_SE2") {
      int id;
      Pose p;
      s >> id >> p.x >> p.y >> p.theta;
      vertices[id] = p;
    } else if (tag == "EDGE_SE2") {
      Edge e;
      double u[6];
      s >> e.i >> e.j >> e.z.x >> e.z.y >> e.z.theta >> u[0] >> u[1] >> u[2] >> u[3] >> u[4] >> u[5];
      e.omega << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
      edges.push_back(e);
    }
  }
  double chi2 = 0.0;
  for (const Edge& e : edges) {
    const Eigen::Matrix3d E = v2t(e.z).inverse() * (v2t(vertices.at(e.i)).inverse() * v2t(vertices.at(e.j)));
    const Eigen::Vector3d r(E(0, 2), E(1, 2), std::atan2(E(1, 0), E(0, 0)));
    chi2 += r.dot(e.omega * r);
  }
  return chi2;
}

void count_lines(void* user, const char* /*line*/) { ++*static_cast<int*>(user); }

struct Reference {
  const char* file;
  double chi2;
};

TEST(CApiPosegraph, ReachesTheReferenceOptimaAndWritesWhatItReports) {
  test::ScratchDir dir;
  for (const Reference& ref : {Reference{"ring.g2o", 11.1631}, Reference{"intel.g2o", 546.461}}) {
    const fs::path in = test::shared_dir() / "data" / "posegraphs" / ref.file;
    const fs::path out = dir / (std::string("opt_") + ref.file);
    planarvo_posegraph_options o;
    planarvo_posegraph_options_init(&o);
    int log_lines = 0;
    o.log = count_lines;
    o.log_user_data = &log_lines;
    planarvo_solver_summary s{};
    s.struct_size = sizeof s;
    ASSERT_EQ(planarvo_posegraph_optimize(in.string().c_str(), out.string().c_str(), &o, &s), PLANARVO_OK)
        << planarvo_last_error();
    // The initial chi^2 is that of the file as given; the final one that of the written graph.
    EXPECT_NEAR(s.initial_chi2, chi2_of_file(in), 1e-9 * s.initial_chi2) << ref.file;
    EXPECT_NEAR(s.final_chi2, chi2_of_file(out), 1e-6 * s.final_chi2) << ref.file;
    // The reference optimum, to the digits the README gives.
    EXPECT_NEAR(s.final_chi2, ref.chi2, 5e-4 * ref.chi2) << ref.file;
    EXPECT_GT(s.iterations, 0);
    EXPECT_GE(s.factorizations, s.iterations);
    EXPECT_GT(log_lines, 0) << "the log callback was not called";
  }
}

TEST(CApiPosegraph, WithoutAnOutputPathWritesNothingAndReportsTheSame) {
  const fs::path in = test::shared_dir() / "data" / "posegraphs" / "ring.g2o";
  planarvo_solver_summary s{};
  s.struct_size = sizeof s;
  ASSERT_EQ(planarvo_posegraph_optimize(in.string().c_str(), nullptr, nullptr, &s), PLANARVO_OK)
      << planarvo_last_error();
  EXPECT_NEAR(s.final_chi2, 11.1631, 5e-4 * 11.1631);
}

TEST(CApiPosegraph, BadInputIsAStatusWithAMessage) {
  test::ScratchDir dir;
  planarvo_solver_summary s{};
  s.struct_size = sizeof s;
  const std::string missing = (dir / "missing.g2o").string();
  EXPECT_EQ(planarvo_posegraph_optimize(missing.c_str(), nullptr, nullptr, &s), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_NE(std::string(planarvo_last_error()).find("missing.g2o"), std::string::npos) << planarvo_last_error();

  const fs::path bad = dir / "bad.g2o";
  std::ofstream(bad) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 inf 1 0 0 1 0 1\n";
  const std::string out = (dir / "out.g2o").string();
  EXPECT_EQ(planarvo_posegraph_optimize(bad.string().c_str(), out.c_str(), nullptr, &s),
            PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_NE(std::string(planarvo_last_error()).find("bad.g2o:3"), std::string::npos) << planarvo_last_error();
  EXPECT_FALSE(fs::exists(out));

  const fs::path ring = test::shared_dir() / "data" / "posegraphs" / "ring.g2o";
  planarvo_posegraph_options o;
  planarvo_posegraph_options_init(&o);
  o.max_iterations = 0;
  EXPECT_EQ(planarvo_posegraph_optimize(ring.string().c_str(), nullptr, &o, &s), PLANARVO_ERROR_INVALID_ARGUMENT);
  planarvo_posegraph_options_init(&o);
  o.init = static_cast<planarvo_posegraph_init>(7);  // not a value of the enum
  EXPECT_EQ(planarvo_posegraph_optimize(ring.string().c_str(), nullptr, &o, &s), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("init"), std::string::npos) << planarvo_last_error();
  EXPECT_EQ(planarvo_posegraph_optimize(nullptr, nullptr, nullptr, &s), PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(planarvo_posegraph_optimize(ring.string().c_str(), nullptr, nullptr, nullptr),
            PLANARVO_ERROR_INVALID_ARGUMENT);
}

}  // namespace
}  // namespace planarvo
