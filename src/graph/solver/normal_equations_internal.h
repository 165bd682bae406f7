// What the three files of NormalEquations (normal_equations.h) share: the clock of the phase
// times. Internal to src/graph.
#pragma once
#include <chrono>

namespace planarvo::graph::normal_equations_detail {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace planarvo::graph::normal_equations_detail
