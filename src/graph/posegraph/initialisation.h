// Initial values for pose graphs, so that Levenberg–Marquardt starts in the basin of the global
// optimum. Both use the graph's RelativePoseFactors between poses and ignore other factors; the
// anchors are the fixed poses (or, when no pose is fixed, the first pose of each connected
// part). Poses not connected to an anchor keep their values.
#pragma once
#include "graph/solver/factor_graph.h"

namespace planarvo::graph {

// Chains the measurements along a breadth-first spanning tree from the anchors:
// X_j = X_i · Z_ij (odometry chaining when the graph is a trajectory).
void initialise_spanning_tree(FactorGraph& graph);

// Rotation first, then translation (LAGO, Carlone et al. 2014): orientations from the linear
// least-squares problem θ_j − θ_i = Z_θ + 2πk_ij, the wraps k_ij taken from the spanning-tree
// orientations and re-estimated once from the solution; then positions from the linear problem
// t_j − t_i = R(θ_i)·Z_t with those orientations. Both weighted by the factors' information.
// Returns the number of edges whose wrap was re-estimated.
int initialise_rotation_first(FactorGraph& graph);

}  // namespace planarvo::graph
