// Synthetic calibration graphs for the benchmarks (paper sec. 5.2.1, fig. 2): a robot trajectory
// of constant-curvature intervals (forwards, backwards, turning in place), wheel odometry and
// up-to-scale sensor motions with noise, poses chained from odometry, the calibration node z
// starting at (0, 0, 1, 0) and the truth from the paper's camera configuration 1.
#pragma once
#include <cmath>
#include <random>

#include <Eigen/Core>

#include "graph/solver/factor_graph.h"
#include "graph/calibration/factors.h"
#include "graph/posegraph/factors.h"

namespace planarvo::bench {

struct SyntheticCalibration {
  graph::FactorGraph graph;
  graph::VariableId z = -1;
  Eigen::Vector4d truth;
};

inline SyntheticCalibration make_calibration_graph(int intervals, unsigned seed) {
  using graph::CalibrationIndex;
  SyntheticCalibration s;
  s.truth << 0.2441, -0.0185, 0.1787, -9.2 * M_PI / 180;
  const double odo_sigma = 0.005, sensor_sigma = 0.003;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> g(0, 1);
  const SE2 T(s.truth[CalibrationIndex::kX], s.truth[CalibrationIndex::kY],
              s.truth[CalibrationIndex::kYaw]);
  s.z = s.graph.add_vector(Eigen::Vector4d(0, 0, 1, 0), "z", graph::calibration_parameter_names());
  graph::VariableId prev = s.graph.add_pose(SE2());
  s.graph.set_fixed(prev);
  const Eigen::Matrix3d odo_info = Eigen::Matrix3d::Identity() / (odo_sigma * odo_sigma);
  const Eigen::Matrix3d sensor_info = Eigen::Matrix3d::Identity() / (sensor_sigma * sensor_sigma);
  for (int k = 0; k < intervals; ++k) {
    const int kind = k % 5;  // 0: turn in place, 1, 2: forwards, 3, 4: backwards
    const double v = kind == 0 ? 0.0 : (kind <= 2 ? 1 : -1) * (0.1 + 0.3 * std::abs(u(rng)));
    const SE2 robot = SE2::exp(Eigen::Vector3d(v, 0.0, 0.8 * u(rng)));
    const SE2 odometry =
        robot * SE2::exp(odo_sigma * Eigen::Vector3d(g(rng), g(rng), g(rng)));
    const SE2 s_metric = T.inverse() * robot * T;
    const double h = s.truth[CalibrationIndex::kHeight];
    const SE2 sensor = SE2(s_metric.x / h, s_metric.y / h, s_metric.theta) *
                       SE2::exp(sensor_sigma * Eigen::Vector3d(g(rng), g(rng), g(rng)));
    const graph::VariableId next = s.graph.add_pose(s.graph.pose(prev) * odometry);
    s.graph.emplace_factor<graph::OdometryFactor>(prev, next, odometry, odo_info);
    s.graph.emplace_factor<graph::SensorMotionFactor>(prev, next, s.z, sensor, sensor_info);
    prev = next;
  }
  return s;
}

}  // namespace planarvo::bench
