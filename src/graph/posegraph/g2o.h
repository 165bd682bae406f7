// g2o's text format for 2-D pose graphs: `VERTEX_SE2 id x y θ`, `EDGE_SE2 i j dx dy dθ I11 I12
// I13 I22 I23 I33` (the upper triangle of the information), `FIX id`; '#' starts a comment.
// Errors name the file and the line.
#pragma once
#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "core/se2.h"
#include "graph/solver/factor_graph.h"

namespace planarvo::graph {

struct G2oVertex {
  int id = 0;
  SE2 pose;
};

struct G2oEdge {
  int from = 0, to = 0;  // vertex ids
  SE2 measurement;
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
};

struct G2oFile {
  std::vector<G2oVertex> vertices;  // in file order
  std::vector<G2oEdge> edges;       // in file order
  std::vector<int> fixed;           // ids named by FIX lines
};

G2oFile read_g2o(const std::filesystem::path& path);
void write_g2o(const std::filesystem::path& path, const G2oFile& file);

// A factor graph with one pose per vertex (variable i is vertices[i]) and one
// RelativePoseFactor per edge (factor k is edges[k]). The vertices named by FIX are fixed, and
// so is the first vertex when `fix_first_vertex` (the benchmarks' gauge).
FactorGraph make_pose_graph(const G2oFile& file, bool fix_first_vertex = true);

// Copies the graph's poses back into the file's vertices (variable i → vertices[i]).
void update_poses(G2oFile& file, const FactorGraph& graph);

}  // namespace planarvo::graph
