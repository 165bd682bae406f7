// The factors of planar pose graphs: relative poses (g2o's EDGE_SE2, the paper's eq. 25) and priors
// on a pose or a vector. The graph calibration's own factors are in calibration/factors.h.
#pragma once
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/se2.h"
#include "graph/solver/factor.h"

namespace planarvo::graph {

// Relative pose between two poses, g2o's EDGE_SE2 exactly: e = t2v(Z⁻¹ · (X_i⁻¹ · X_j)), the
// angle wrapped to (-π, π]. This is also the paper's wheel-odometry factor, eq. 25:
// e = (r_{i+1} ⊖ r_i) ⊖ w with a ⊖ b = b⁻¹·a.
class RelativePoseFactor final : public Factor {
 public:
  RelativePoseFactor(VariableId from, VariableId to, const SE2& measurement,
                     const Eigen::Matrix3d& information);
  void evaluate(const double* const* values, double* error,
                double* const* jacobians) const override;
  const SE2& measurement() const { return measurement_; }

 private:
  SE2 measurement_;
  double cz_, sz_;  // cos, sin of the measured angle
};

// The paper's odometry factor (eq. 25) is the relative-pose factor.
using OdometryFactor = RelativePoseFactor;

// Prior on a pose: e = t2v(Z⁻¹ · X) (g2o's EDGE_SE2_PRIOR).
class PosePriorFactor final : public Factor {
 public:
  PosePriorFactor(VariableId pose, const SE2& prior, const Eigen::Matrix3d& information);
  void evaluate(const double* const* values, double* error,
                double* const* jacobians) const override;

 private:
  SE2 prior_;
  double cz_, sz_;
};

// Prior on a vector variable: e = x − μ.
class VectorPriorFactor final : public Factor {
 public:
  VectorPriorFactor(VariableId variable, const Eigen::VectorXd& prior,
                    const Eigen::MatrixXd& information);
  void evaluate(const double* const* values, double* error,
                double* const* jacobians) const override;

 private:
  Eigen::VectorXd prior_;
};

}  // namespace planarvo::graph
