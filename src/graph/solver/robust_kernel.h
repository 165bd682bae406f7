// Robust kernels ρ(s) of the squared whitened error s = eᵀΩe (ρ(s) ≈ s for small s, so a
// robust cost reads in χ² units for inliers).
//
// The solver uses the square-root weight form (IRLS): r̃ = √ρ'(s)·r, J̃ = √ρ'(s)·J. This gives
// the exact gradient ρ'(s)·Jᵀr of the robust cost. Triggs' second-order correction (the one
// Ceres applies) changes the step only where ρ''(s) > 0; all three kernels here are concave in s
// (ρ'' ≤ 0), where Ceres, too, falls back to this form because the corrected Gauss–Newton
// matrix may become indefinite.
#pragma once
#include <memory>
#include <string>

namespace planarvo::graph {

class RobustKernel {
 public:
  virtual ~RobustKernel() = default;
  // rho[0] = ρ(s), rho[1] = ρ'(s), rho[2] = ρ''(s), for s ≥ 0.
  virtual void evaluate(double s, double rho[3]) const = 0;
  virtual std::string name() const = 0;
};

// ρ(s) = s for s ≤ δ², 2δ√s − δ² beyond: quadratic near zero, linear in |e| for outliers.
class HuberKernel final : public RobustKernel {
 public:
  explicit HuberKernel(double delta);
  void evaluate(double s, double rho[3]) const override;
  std::string name() const override;

 private:
  double delta_, delta2_;
};

// ρ(s) = c² log(1 + s/c²): logarithmic growth, weight ρ' = 1 / (1 + s/c²).
class CauchyKernel final : public RobustKernel {
 public:
  explicit CauchyKernel(double c);
  void evaluate(double s, double rho[3]) const override;
  std::string name() const override;

 private:
  double c_, c2_;
};

// Tukey's biweight: ρ(s) = c²/3 (1 − (1 − s/c²)³) for s ≤ c², c²/3 beyond; weight
// ρ' = (1 − s/c²)², zero for outliers (they leave the problem entirely).
class TukeyKernel final : public RobustKernel {
 public:
  explicit TukeyKernel(double c);
  void evaluate(double s, double rho[3]) const override;
  std::string name() const override;

 private:
  double c_, c2_;
};

using RobustKernelPtr = std::shared_ptr<const RobustKernel>;

}  // namespace planarvo::graph
