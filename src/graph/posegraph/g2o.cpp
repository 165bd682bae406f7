#include "graph/posegraph/g2o.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <unordered_map>

#include <Eigen/Cholesky>

#include "core/error.h"
#include "core/output_file.h"
#include "graph/posegraph/factors.h"

namespace planarvo::graph {
namespace {

// Reads whitespace-separated fields of one line, reporting errors with file and line.
class LineReader {
 public:
  LineReader(const std::filesystem::path& path, int line, const char* text, const char* end)
      : path_(path), line_(line), p_(text), end_(end) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw_invalid_input(path_.string() + ":" + std::to_string(line_) + ": " + what);
  }
  // std::from_chars: exact, independent of the C locale (strtod reads "1,5" in a German one);
  // the one thing of strtod's it does not take, a leading '+', is skipped first.
  double number(const char* field) {
    skip_space();
    const char* b = p_ + (*p_ == '+' && p_ + 1 < end_ && p_[1] != '-' && p_[1] != '+');
    double v = 0.0;
    const auto [end, ec] = std::from_chars(b, end_, v);
    if (ec != std::errc() || end == b || !is_end(*end))
      fail(std::string("expected a number for ") + field);
    p_ = end;
    return v;
  }
  int integer(const char* field) {
    skip_space();
    const char* b = p_ + (*p_ == '+' && p_ + 1 < end_ && p_[1] != '-' && p_[1] != '+');
    int v = 0;
    const auto [end, ec] = std::from_chars(b, end_, v);
    if (ec != std::errc() || end == b || !is_end(*end))
      fail(std::string("expected an integer for ") + field);
    p_ = end;
    return v;
  }
  void expect_end() {
    skip_space();
    if (*p_ != '\0' && *p_ != '#') fail("unexpected text after the last field");
  }

 private:
  static bool is_end(char c) { return c == '\0' || c == ' ' || c == '\t' || c == '\r' || c == '#'; }
  void skip_space() {
    while (*p_ == ' ' || *p_ == '\t' || *p_ == '\r') ++p_;
  }
  const std::filesystem::path& path_;
  int line_;
  const char* p_;
  const char* end_;  // the line's terminating '\0'
};

}  // namespace

G2oFile read_g2o(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw_invalid_input(path.string() + ": cannot open the file");
  G2oFile file;
  std::unordered_map<int, int> index_of;  // vertex id → index
  std::vector<int> edge_lines;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    size_t a = line.find_first_not_of(" \t\r");
    if (a == std::string::npos || line[a] == '#') continue;
    size_t b = line.find_first_of(" \t\r", a);
    if (b == std::string::npos) b = line.size();
    const std::string tag = line.substr(a, b - a);
    LineReader r(path, line_no, line.c_str() + b, line.c_str() + line.size());
    if (tag == "VERTEX_SE2") {
      G2oVertex v;
      v.id = r.integer("the vertex id");
      v.pose.x = r.number("x");
      v.pose.y = r.number("y");
      v.pose.theta = r.number("theta");
      r.expect_end();
      if (!std::isfinite(v.pose.x) || !std::isfinite(v.pose.y) || !std::isfinite(v.pose.theta))
        r.fail("the vertex pose is not finite");
      v.pose.theta = wrap_angle(v.pose.theta);
      if (!index_of.emplace(v.id, static_cast<int>(file.vertices.size())).second)
        r.fail("vertex " + std::to_string(v.id) + " is defined twice");
      file.vertices.push_back(v);
    } else if (tag == "EDGE_SE2") {
      G2oEdge e;
      e.from = r.integer("the first vertex id");
      e.to = r.integer("the second vertex id");
      e.measurement.x = r.number("dx");
      e.measurement.y = r.number("dy");
      e.measurement.theta = r.number("dtheta");
      const char* names[6] = {"I11", "I12", "I13", "I22", "I23", "I33"};
      double u[6];
      for (int k = 0; k < 6; ++k) u[k] = r.number(names[k]);
      r.expect_end();
      if (!std::isfinite(e.measurement.x) || !std::isfinite(e.measurement.y) || !std::isfinite(e.measurement.theta))
        r.fail("the edge measurement is not finite");
      e.information << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
      Eigen::LLT<Eigen::Matrix3d> llt(e.information);
      if (!e.information.allFinite() || llt.info() != Eigen::Success)
        r.fail("the information matrix is not positive definite");
      if (e.from == e.to) r.fail("an edge from a vertex to itself");
      e.measurement.theta = wrap_angle(e.measurement.theta);
      file.edges.push_back(e);
      edge_lines.push_back(line_no);
    } else if (tag == "FIX") {
      file.fixed.push_back(r.integer("the vertex id"));
      r.expect_end();
      edge_lines.push_back(-line_no);  // checked below with the edges
    } else {
      r.fail("unsupported element '" + tag + "' (only VERTEX_SE2, EDGE_SE2 and FIX)");
    }
  }
  // Vertices may follow the edges that use them; check references once all are known.
  size_t next_edge = 0, next_fix = 0;
  for (int l : edge_lines) {
    if (l > 0) {
      const G2oEdge& e = file.edges[next_edge++];
      for (int id : {e.from, e.to})
        if (!index_of.count(id))
          throw_invalid_input(path.string() + ":" + std::to_string(l) + ": no vertex " +
                              std::to_string(id));
    } else {
      const int id = file.fixed[next_fix++];
      if (!index_of.count(id))
        throw_invalid_input(path.string() + ":" + std::to_string(-l) + ": no vertex " +
                            std::to_string(id));
    }
  }
  return file;
}

namespace {

// One g2o line built with std::to_chars: the shortest text that reads back as the same double
// (as exact as printf's %.17g, and several times faster on graphs of 10^4 edges).
class G2oLine {
 public:
  explicit G2oLine(const char* tag) { put(tag); }
  G2oLine& operator<<(int v) { return number(v); }
  G2oLine& operator<<(double v) { return number(v); }
  void write(FILE* f) {
    buf_[n_++] = '\n';
    std::fwrite(buf_, 1, n_, f);
  }

 private:
  template <class T>
  G2oLine& number(T v) {
    buf_[n_++] = ' ';
    n_ = static_cast<size_t>(std::to_chars(buf_ + n_, buf_ + sizeof buf_ - 1, v).ptr - buf_);
    return *this;
  }
  void put(const char* text) {
    while (*text) buf_[n_++] = *text++;
  }
  char buf_[512];  // 11 numbers of at most 24 characters, and a tag
  size_t n_ = 0;
};

}  // namespace

void write_g2o(const std::filesystem::path& path, const G2oFile& file) {
  OutputFile out(path.string());  // complete or untouched (core/output_file.h)
  FILE* f = out.stream();
  for (const G2oVertex& v : file.vertices) (G2oLine("VERTEX_SE2") << v.id << v.pose.x << v.pose.y << v.pose.theta).write(f);
  for (const G2oEdge& e : file.edges) {
    const Eigen::Matrix3d& I = e.information;
    (G2oLine("EDGE_SE2") << e.from << e.to << e.measurement.x << e.measurement.y << e.measurement.theta << I(0, 0)
                         << I(0, 1) << I(0, 2) << I(1, 1) << I(1, 2) << I(2, 2))
        .write(f);
  }
  for (int id : file.fixed) (G2oLine("FIX") << id).write(f);
  out.commit();
}

FactorGraph make_pose_graph(const G2oFile& file, bool fix_first_vertex) {
  FactorGraph graph;
  std::unordered_map<int, VariableId> var_of;
  for (const G2oVertex& v : file.vertices)
    var_of[v.id] = graph.add_pose(v.pose, "vertex " + std::to_string(v.id));
  for (const G2oEdge& e : file.edges)
    graph.add_factor(std::make_unique<RelativePoseFactor>(var_of.at(e.from), var_of.at(e.to),
                                                          e.measurement, e.information));
  for (int id : file.fixed) graph.set_fixed(var_of.at(id));
  if (fix_first_vertex && !file.vertices.empty()) graph.set_fixed(0);
  return graph;
}

void update_poses(G2oFile& file, const FactorGraph& graph) {
  if (graph.num_variables() < static_cast<int>(file.vertices.size()))
    throw_invalid_argument("update_poses: the graph has fewer variables than the file vertices");
  for (size_t i = 0; i < file.vertices.size(); ++i)
    file.vertices[i].pose = graph.pose(static_cast<VariableId>(i));
}

}  // namespace planarvo::graph
