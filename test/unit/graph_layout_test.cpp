// The rule src/graph/README.md states for its three folders, checked on the source tree: the
// pose graphs and the calibrations use the solver only through its interface, the solver knows
// neither, and the pose graphs know nothing of the calibrations.
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace planarvo {
namespace {

namespace fs = std::filesystem;

struct Include {
  std::string file;    // relative to src/graph
  std::string target;  // as written, e.g. "graph/solver/solver.h"
};

std::vector<Include> graph_includes() {
  const fs::path root = fs::path(PLANARVO_SOURCE_DIR) / "src" / "graph";
  const std::regex include(R"re(^\s*#\s*include\s+"([^"]+)")re");
  std::vector<Include> out;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".h" && ext != ".cpp") continue;
    std::ifstream in(entry.path());
    std::string line;
    std::smatch m;
    while (std::getline(in, line))
      if (std::regex_search(line, m, include))
        out.push_back({fs::relative(entry.path(), root).generic_string(), m[1].str()});
  }
  return out;
}

std::string folder_of(const std::string& file) { return file.substr(0, file.find('/')); }

TEST(GraphLayout, FoldersUseEachOtherOnlyDownwardsAndTheSolverThroughItsInterface) {
  const std::vector<Include> includes = graph_includes();
  ASSERT_GT(includes.size(), 40u);  // the tree was found
  const std::set<std::string> folders = {"solver", "posegraph", "calibration"};
  // Which folders each may include from.
  const auto allowed = [](const std::string& from, const std::string& to) {
    if (from == to) return true;
    if (from == "posegraph") return to == "solver";
    if (from == "calibration") return to == "solver" || to == "posegraph";
    return false;  // solver: nothing above it
  };
  for (const Include& inc : includes) {
    const std::string from = folder_of(inc.file);
    EXPECT_TRUE(folders.count(from)) << inc.file << ": a file outside the three folders";
    if (inc.target.rfind("graph/", 0) != 0) continue;
    const std::string rest = inc.target.substr(6);
    const std::string to = folder_of(rest);
    EXPECT_TRUE(folders.count(to)) << inc.file << " includes " << inc.target << ", not in a folder";
    EXPECT_TRUE(allowed(from, to)) << inc.file << " includes " << inc.target;
    if (to == "solver" && from != "solver") {
      EXPECT_EQ(rest.find("_internal.h"), std::string::npos) << inc.file << " includes the solver's internals";
    }
  }
}

// And nothing outside src/graph reaches into the solver's internals.
TEST(GraphLayout, TheSolversInternalsStayInTheSolver) {
  const std::regex internal(R"re(#\s*include\s+"graph/solver/[a-z_]+_internal\.h")re");
  for (const char* top : {"src", "test", "ros", "fuzz", "examples"}) {
    const fs::path root = fs::path(PLANARVO_SOURCE_DIR) / top;
    if (!fs::exists(root)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
      const std::string p = entry.path().generic_string();
      if (p.find("/src/graph/solver/") != std::string::npos) continue;
      const std::string ext = entry.path().extension().string();
      if (ext != ".h" && ext != ".cpp") continue;
      std::ifstream in(entry.path());
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      EXPECT_FALSE(std::regex_search(text, internal)) << p;
    }
  }
}

}  // namespace
}  // namespace planarvo
