// A factor graph: variables (poses and small vectors) with their current values, which of them
// (or which of their parameters) are held fixed, and the factors that tie them together.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/se2.h"
#include "graph/solver/factor.h"
#include "graph/solver/robust_kernel.h"

namespace planarvo::graph {

class FactorGraph {
 public:
  FactorGraph() = default;
  // A moved-from graph is empty and gets a new structure version (a solver must not take it for
  // the graph its factors went to).
  FactorGraph(FactorGraph&& other) noexcept;
  FactorGraph& operator=(FactorGraph&& other) noexcept;

  // Variables. Names are for reports ("z", "pose 17"); parameter names for observability reports
  // ("x", "y", "height", "yaw"); both default to something sensible.
  VariableId add_pose(const SE2& value, std::string name = {});
  VariableId add_vector(const Eigen::VectorXd& value, std::string name = {},
                        std::vector<std::string> parameter_names = {});

  // A fixed variable keeps its value; a fixed parameter of a variable keeps its value while the
  // others move (the solver drops its column from the normal equations). For a pose, the
  // parameters are x, y, θ in the world frame (such a pose steps additively, see
  // PoseRetraction).
  void set_fixed(VariableId v, bool fixed = true);
  void set_parameter_fixed(VariableId v, int parameter, bool fixed = true);
  bool is_fixed(VariableId v) const;
  bool is_parameter_fixed(VariableId v, int parameter) const;

  // Adds a factor; checks that its variables exist and have the types it expects. Returns the
  // factor's index. A null kernel means plain least squares.
  int add_factor(std::unique_ptr<Factor> factor, RobustKernelPtr kernel = nullptr);
  template <class F, class... Args>
  int emplace_factor(Args&&... args) {
    return add_factor(std::make_unique<F>(std::forward<Args>(args)...));
  }
  void set_robust_kernel(int factor, RobustKernelPtr kernel);

  // Values.
  SE2 pose(VariableId v) const;
  void set_pose(VariableId v, const SE2& value);
  Eigen::VectorXd vector(VariableId v) const;
  void set_vector(VariableId v, const Eigen::VectorXd& value);

  int num_variables() const { return static_cast<int>(variables_.size()); }
  int num_factors() const { return static_cast<int>(factors_.size()); }
  const Factor& factor(int i) const { return *factors_.at(i).factor; }
  const RobustKernel* robust_kernel(int i) const { return factors_.at(i).kernel.get(); }
  VariableType type(VariableId v) const { return variable(v).type; }
  const std::string& name(VariableId v) const { return variable(v).name; }
  const std::string& parameter_name(VariableId v, int parameter) const;

  // χ² = Σ eᵀΩe over all factors (robust kernels ignored), and the robust cost Σ ρ(eᵀΩe) that
  // the solver minimises (equal to χ² without kernels).
  double chi2() const;
  double robust_cost() const;
  // The first factor whose eᵀΩe is not finite at the current values (finite inputs can still
  // overflow), or -1.
  int first_nonfinite_factor() const;

  // The solver's access to the values: one flat array, variable v's coordinates at offset(v).
  const std::vector<double>& values() const { return values_; }
  void set_values(const std::vector<double>& values);
  int offset(VariableId v) const { return variable(v).offset; }
  // Fixed parameters of v as a bit mask (bit i: parameter i), all bits set when v is fixed.
  std::uint64_t fixed_mask(VariableId v) const;
  // Changes whenever variables, factors, robust kernels or what is fixed change (the solver's
  // symbolic analysis stays valid while it does not). Versions come from one process-wide
  // counter, so two graphs never share one; a moved graph keeps its version (its factors keep
  // their addresses).
  std::uint64_t structure_version() const { return version_; }

 private:
  struct Variable {
    VariableType type;
    int offset = 0;
    bool fixed = false;
    std::uint64_t fixed_parameters = 0;
    std::string name;
    std::vector<std::string> parameter_names;
  };
  struct Entry {
    std::unique_ptr<Factor> factor;
    RobustKernelPtr kernel;
  };
  const Variable& variable(VariableId v) const;
  Variable& variable(VariableId v);
  VariableId add_variable(VariableType type, const double* value, std::string name,
                          std::vector<std::string> parameter_names);

  std::vector<Variable> variables_;
  std::vector<double> values_;
  std::vector<Entry> factors_;
  void touch();  // a new structure version

  std::uint64_t version_ = 0;
};

}  // namespace planarvo::graph
