// Numbers out of the tool's printed text and written files, for tests that compare what
// `planarvo` prints and writes with the same computation done through the C API or with an
// independent reference (the simulator's truth, a plain computation in the test).
#pragma once
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

namespace planarvo::test {

// The first line of text that contains label, "" when there is none.
inline std::string line_with(const std::string& text, const std::string& label) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.find(label) != std::string::npos) return line;
  return "";
}

// Every number in s, in order: a number starts at a digit, or a sign or point before a digit,
// that does not continue a word ("x480", "p1" and "k3" hold none).
inline std::vector<double> numbers_in(const std::string& s) {
  std::vector<double> out;
  const char* p = s.c_str();
  const char* begin = p;
  while (*p) {
    const bool word = p > begin && (std::isalnum(static_cast<unsigned char>(p[-1])) || p[-1] == '_' || p[-1] == '.');
    const bool digit = std::isdigit(static_cast<unsigned char>(*p)) != 0;
    const bool sign = (*p == '-' || *p == '+' || *p == '.') &&
                      (std::isdigit(static_cast<unsigned char>(p[1])) ||
                       (p[1] == '.' && std::isdigit(static_cast<unsigned char>(p[2]))));
    if (!word && (digit || sign)) {
      char* end = nullptr;
      const double v = std::strtod(p, &end);
      if (end != p) {
        out.push_back(v);
        p = end;
        continue;
      }
    }
    ++p;
  }
  return out;
}

// The numbers after label on the first line that contains it (none: an empty vector).
inline std::vector<double> numbers_after(const std::string& text, const std::string& label) {
  const std::string line = line_with(text, label);
  if (line.empty()) return {};
  return numbers_in(line.substr(line.find(label) + label.size()));
}

// Asserts that printed, a value printed with `decimals` digits after the point, is value rounded.
inline void expect_printed(double printed, double value, int decimals, const std::string& what) {
  const double half = 0.5 * std::pow(10.0, -decimals);
  EXPECT_NEAR(printed, value, half * (1 + 1e-9) + 1e-12 * std::abs(value)) << what;
}

// One CSV file as rows of fields (the header line, when `header`, left out).
inline std::vector<std::vector<std::string>> read_csv(const std::string& path, bool header = true) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  if (header) std::getline(in, line);
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;  // every field, a trailing empty one too
    size_t start = 0;
    for (size_t comma; (comma = line.find(',', start)) != std::string::npos; start = comma + 1)
      fields.push_back(line.substr(start, comma - start));
    fields.push_back(line.substr(start));
    rows.push_back(fields);
  }
  return rows;
}

// chi^2 = sum e' Omega e, e = t2v(Z^-1 (X_i^-1 X_j)) (g2o's convention), over the EDGE_SE2 lines
// of a g2o file, computed here in plain Eigen, not by the solver's code.
inline double g2o_chi2(const std::string& path) {
  struct Pose {
    double x = 0, y = 0, theta = 0;
  };
  auto v2t = [](const Pose& p) {
    Eigen::Matrix3d T;
    T << std::cos(p.theta), -std::sin(p.theta), p.x, std::sin(p.theta), std::cos(p.theta), p.y, 0, 0, 1;
    return T;
  };
  std::ifstream in(path);
  std::unordered_map<int, Pose> vertices;
  struct Edge {
    int i = 0, j = 0;
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
      int id = 0;
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

}  // namespace planarvo::test
