// planarvo_posegraph_optimize through the C API, against independent references: the shared
// graphs' reference optima (reached by Ceres Solver and g2o, ../shared/data/posegraphs/README.md),
// and the chi^2 of the written graph recomputed here from the file with g2o's error convention
// in plain Eigen (not the solver's code); a small graph whose optimum is solved by hand, with and
// without FIX; rotation-first initialisation; an iteration cap that stops it early. Also: no output
// path, the log callback, bad input.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/printed_values.h"
#include "common/test_util.h"
#include "planarvo/planarvo.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;

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
    EXPECT_NEAR(s.initial_chi2, test::g2o_chi2(in.string()), 1e-9 * s.initial_chi2) << ref.file;
    EXPECT_NEAR(s.final_chi2, test::g2o_chi2(out.string()), 1e-6 * s.final_chi2) << ref.file;
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

// The x coordinates of the VERTEX_SE2 lines of a g2o file, by id.
std::vector<double> vertex_x(const fs::path& path) {
  std::ifstream in(path);
  std::vector<double> x;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    int id = 0;
    double v = 0;
    if ((s >> tag >> id >> v) && tag == "VERTEX_SE2") {
      if (x.size() <= static_cast<size_t>(id)) x.resize(static_cast<size_t>(id) + 1);
      x[static_cast<size_t>(id)] = v;
    }
  }
  return x;
}

// Three poses on a line, two unit steps and a loop closure of 2.1, unit information: the
// optimum is linear least squares solved by hand. Free: x1 = 3.1 / 3, x2 = 6.2 / 3, each
// residual 0.1 / 3, chi^2 = 3 (0.1 / 3)^2. With FIX 2 (x2 held at 2.1): x1 = 1.05, chi^2 =
// 2 * 0.05^2.
TEST(CApiPosegraph, ASmallGraphReachesTheOptimumSolvedByHand) {
  test::ScratchDir dir;
  const std::string graph =
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0.5 0 0\nVERTEX_SE2 2 2.1 0 0\n"
      "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 1 2 1 0 0 1 0 0 1 0 1\nEDGE_SE2 0 2 2.1 0 0 1 0 0 1 0 1\n";
  struct Case {
    const char* name;
    std::string text;
    double x1, x2, chi2;
  };
  const Case cases[] = {{"free", graph, 3.1 / 3, 6.2 / 3, 3 * (0.1 / 3) * (0.1 / 3)},
                        {"fix", graph + "FIX 2\n", 1.05, 2.1, 2 * 0.05 * 0.05}};
  for (const Case& c : cases) {
    const fs::path in = dir / (std::string(c.name) + ".g2o"), out = dir / (std::string(c.name) + "_opt.g2o");
    std::ofstream(in) << c.text;
    planarvo_solver_summary s{};
    s.struct_size = sizeof s;
    ASSERT_EQ(planarvo_posegraph_optimize(in.string().c_str(), out.string().c_str(), nullptr, &s), PLANARVO_OK)
        << planarvo_last_error();
    const std::vector<double> x = vertex_x(out);
    ASSERT_EQ(x.size(), 3u) << c.name;
    EXPECT_EQ(x[0], 0.0) << c.name;  // the first vertex is held
    EXPECT_NEAR(x[1], c.x1, 1e-7) << c.name;  // LM stops on the cost's relative change
    EXPECT_NEAR(x[2], c.x2, 1e-7) << c.name;
    EXPECT_NEAR(s.final_chi2, c.chi2, 1e-10) << c.name;
    EXPECT_NEAR(test::g2o_chi2(out.string()), c.chi2, 1e-10) << c.name;
    EXPECT_NEAR(s.initial_chi2, test::g2o_chi2(in.string()), 1e-12) << c.name;
    EXPECT_EQ(s.converged, 1) << c.name;
  }
}

// Rotation-first initialisation (LAGO) then Levenberg-Marquardt reaches the same optima.
TEST(CApiPosegraph, RotationFirstInitialisationReachesTheReferenceOptima) {
  for (const Reference& ref : {Reference{"ring.g2o", 11.1631}, Reference{"intel.g2o", 546.461}}) {
    const fs::path in = test::shared_dir() / "data" / "posegraphs" / ref.file;
    planarvo_posegraph_options o;
    planarvo_posegraph_options_init(&o);
    o.init = PLANARVO_POSEGRAPH_INIT_ROTATION_FIRST;
    planarvo_solver_summary s{};
    s.struct_size = sizeof s;
    ASSERT_EQ(planarvo_posegraph_optimize(in.string().c_str(), nullptr, &o, &s), PLANARVO_OK) << planarvo_last_error();
    EXPECT_NEAR(s.initial_chi2, test::g2o_chi2(in.string()), 1e-9 * s.initial_chi2) << ref.file;
    EXPECT_NEAR(s.final_chi2, ref.chi2, 5e-4 * ref.chi2) << ref.file;
  }
}

// An iteration cap that stops the solver early: PLANARVO_ERROR_FAILED saying why, and the graph
// it reached written all the same, with the chi^2 it reports.
TEST(CApiPosegraph, AnIterationCapIsFailedAndStillWritesTheGraph) {
  test::ScratchDir dir;
  const fs::path in = test::shared_dir() / "data" / "posegraphs" / "intel.g2o";
  const fs::path out = dir / "capped.g2o";
  planarvo_posegraph_options o;
  planarvo_posegraph_options_init(&o);
  o.max_iterations = 1;
  planarvo_solver_summary s{};
  s.struct_size = sizeof s;
  EXPECT_EQ(planarvo_posegraph_optimize(in.string().c_str(), out.string().c_str(), &o, &s), PLANARVO_ERROR_FAILED);
  EXPECT_NE(std::string(planarvo_last_error()).find("did not converge"), std::string::npos) << planarvo_last_error();
  EXPECT_EQ(s.converged, 0);
  EXPECT_EQ(s.iterations, 1);
  EXPECT_LT(s.final_chi2, s.initial_chi2);
  EXPECT_GT(s.final_chi2, 546.461 + 0.01);  // short of the optimum
  ASSERT_TRUE(fs::exists(out));
  EXPECT_NEAR(test::g2o_chi2(out.string()), s.final_chi2, 1e-6 * s.final_chi2);
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
  planarvo_solver_summary small{};
  small.struct_size = 8;  // older than the first version
  EXPECT_EQ(planarvo_posegraph_optimize(ring.string().c_str(), nullptr, nullptr, &small),
            PLANARVO_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(planarvo_last_error()).find("planarvo_solver_summary"), std::string::npos)
      << planarvo_last_error();
  const fs::path empty = dir / "empty.g2o";
  std::ofstream(empty) << "# no vertices\n";
  EXPECT_EQ(planarvo_posegraph_optimize(empty.string().c_str(), nullptr, nullptr, &s), PLANARVO_ERROR_INVALID_INPUT);
  EXPECT_NE(std::string(planarvo_last_error()).find("empty.g2o"), std::string::npos) << planarvo_last_error();
}

}  // namespace
}  // namespace planarvo
