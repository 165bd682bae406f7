#include "graph/solver/factor_graph.h"

#include <atomic>
#include <cmath>

#include "core/error.h"

namespace planarvo::graph {
namespace {

constexpr int kMaxVectorDim = 64;  // the fixed-parameter mask is one 64-bit word

}  // namespace

void FactorGraph::touch() {
  static std::atomic<std::uint64_t> counter{0};
  version_ = ++counter;
}

FactorGraph::FactorGraph(FactorGraph&& other) noexcept { *this = std::move(other); }

FactorGraph& FactorGraph::operator=(FactorGraph&& other) noexcept {
  if (this == &other) return *this;
  variables_ = std::move(other.variables_);
  values_ = std::move(other.values_);
  factors_ = std::move(other.factors_);
  version_ = other.version_;
  other.variables_.clear();
  other.values_.clear();
  other.factors_.clear();
  other.touch();
  return *this;
}

const FactorGraph::Variable& FactorGraph::variable(VariableId v) const {
  if (v < 0 || v >= num_variables())
    throw_invalid_argument("FactorGraph: no variable " + std::to_string(v));
  return variables_[static_cast<size_t>(v)];
}

FactorGraph::Variable& FactorGraph::variable(VariableId v) {
  return const_cast<Variable&>(static_cast<const FactorGraph*>(this)->variable(v));
}

VariableId FactorGraph::add_variable(VariableType type, const double* value, std::string name,
                                     std::vector<std::string> parameter_names) {
  for (int i = 0; i < type.dim; ++i)
    if (!std::isfinite(value[i]))
      throw_invalid_argument("FactorGraph: the initial value of '" + name + "' is not finite");
  const auto id = static_cast<VariableId>(variables_.size());
  Variable var;
  var.type = type;
  var.offset = static_cast<int>(values_.size());
  var.name = name.empty() ? (type.kind == VariableKind::Pose2 ? "pose " : "vector ") +
                                std::to_string(id)
                          : std::move(name);
  if (parameter_names.empty()) {
    if (type.kind == VariableKind::Pose2) {
      parameter_names = {"x", "y", "theta"};
    } else {
      for (int i = 0; i < type.dim; ++i) parameter_names.push_back("p" + std::to_string(i));
    }
  }
  if (static_cast<int>(parameter_names.size()) != type.dim)
    throw_invalid_argument("FactorGraph: '" + var.name + "' needs one name per parameter");
  var.parameter_names = std::move(parameter_names);
  values_.insert(values_.end(), value, value + type.dim);
  if (type.kind == VariableKind::Pose2) values_.back() = wrap_angle(values_.back());
  variables_.push_back(std::move(var));
  touch();
  return id;
}

VariableId FactorGraph::add_pose(const SE2& value, std::string name) {
  const double v[3] = {value.x, value.y, value.theta};
  return add_variable(VariableType::pose2(), v, std::move(name), {});
}

VariableId FactorGraph::add_vector(const Eigen::VectorXd& value, std::string name,
                                   std::vector<std::string> parameter_names) {
  if (value.size() < 1 || value.size() > kMaxVectorDim)
    throw_invalid_argument("FactorGraph: a vector variable has 1 to 64 components");
  return add_variable(VariableType::vector(static_cast<int>(value.size())), value.data(),
                      std::move(name), std::move(parameter_names));
}

void FactorGraph::set_fixed(VariableId v, bool fixed) {
  variable(v).fixed = fixed;
  touch();
}

void FactorGraph::set_parameter_fixed(VariableId v, int parameter, bool fixed) {
  Variable& var = variable(v);
  if (parameter < 0 || parameter >= var.type.dim)
    throw_invalid_argument("FactorGraph: '" + var.name + "' has no parameter " +
                           std::to_string(parameter));
  const std::uint64_t bit = std::uint64_t{1} << parameter;
  var.fixed_parameters = fixed ? (var.fixed_parameters | bit) : (var.fixed_parameters & ~bit);
  touch();
}

bool FactorGraph::is_fixed(VariableId v) const { return variable(v).fixed; }

bool FactorGraph::is_parameter_fixed(VariableId v, int parameter) const {
  const Variable& var = variable(v);
  if (parameter < 0 || parameter >= var.type.dim)
    throw_invalid_argument("FactorGraph: '" + var.name + "' has no parameter " +
                           std::to_string(parameter));
  return var.fixed || ((var.fixed_parameters >> parameter) & 1u);
}

std::uint64_t FactorGraph::fixed_mask(VariableId v) const {
  const Variable& var = variable(v);
  if (!var.fixed) return var.fixed_parameters;
  return var.type.dim >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << var.type.dim) - 1;
}

const std::string& FactorGraph::parameter_name(VariableId v, int parameter) const {
  const Variable& var = variable(v);
  if (parameter < 0 || parameter >= var.type.dim)
    throw_invalid_argument("FactorGraph: '" + var.name + "' has no parameter " +
                           std::to_string(parameter));
  return var.parameter_names[static_cast<size_t>(parameter)];
}

int FactorGraph::add_factor(std::unique_ptr<Factor> factor, RobustKernelPtr kernel) {
  if (!factor) throw_invalid_argument("FactorGraph::add_factor: null factor");
  const auto& vars = factor->variables();
  const auto& types = factor->types();
  for (size_t k = 0; k < vars.size(); ++k) {
    if (vars[k] < 0 || vars[k] >= num_variables())
      throw_invalid_argument("FactorGraph::add_factor: no variable " + std::to_string(vars[k]));
    if (!(variable(vars[k]).type == types[k]))
      throw_invalid_argument("FactorGraph::add_factor: '" + variable(vars[k]).name + "' is a " +
                             to_string(variable(vars[k]).type) + ", the factor expects a " +
                             to_string(types[k]));
    for (size_t l = 0; l < k; ++l)
      if (vars[l] == vars[k])
        throw_invalid_argument("FactorGraph::add_factor: a factor names '" +
                               variable(vars[k]).name + "' twice");
  }
  factors_.push_back({std::move(factor), std::move(kernel)});
  touch();
  return num_factors() - 1;
}

void FactorGraph::set_robust_kernel(int factor, RobustKernelPtr kernel) {
  factors_.at(static_cast<size_t>(factor)).kernel = std::move(kernel);
  touch();  // the solver holds the kernel's address
}

SE2 FactorGraph::pose(VariableId v) const {
  const Variable& var = variable(v);
  if (var.type.kind != VariableKind::Pose2)
    throw_invalid_argument("FactorGraph: '" + var.name + "' is not a pose");
  const double* x = &values_[static_cast<size_t>(var.offset)];
  return {x[0], x[1], x[2]};
}

void FactorGraph::set_pose(VariableId v, const SE2& value) {
  const Variable& var = variable(v);
  if (var.type.kind != VariableKind::Pose2)
    throw_invalid_argument("FactorGraph: '" + var.name + "' is not a pose");
  double* x = &values_[static_cast<size_t>(var.offset)];
  x[0] = value.x;
  x[1] = value.y;
  x[2] = wrap_angle(value.theta);
}

Eigen::VectorXd FactorGraph::vector(VariableId v) const {
  const Variable& var = variable(v);
  return Eigen::Map<const Eigen::VectorXd>(&values_[static_cast<size_t>(var.offset)],
                                           var.type.dim);
}

void FactorGraph::set_vector(VariableId v, const Eigen::VectorXd& value) {
  const Variable& var = variable(v);
  if (var.type.kind != VariableKind::Vector || value.size() != var.type.dim)
    throw_invalid_argument("FactorGraph: '" + var.name + "' is not a vector of " +
                           std::to_string(value.size()));
  Eigen::Map<Eigen::VectorXd>(&values_[static_cast<size_t>(var.offset)], var.type.dim) = value;
}

void FactorGraph::set_values(const std::vector<double>& values) {
  if (values.size() != values_.size())
    throw_invalid_argument("FactorGraph::set_values: wrong number of values");
  values_ = values;
}

namespace {

// Σ over factors of f(s) with s = eᵀΩe; allocation per call is fine here (not the solver's loop).
template <class F>
double sum_over_factors(const FactorGraph& g, F&& f) {
  double total = 0.0;
  std::vector<const double*> ptrs;
  Eigen::VectorXd e, r;
  Eigen::MatrixXd L;
  for (int i = 0; i < g.num_factors(); ++i) {
    const Factor& fac = g.factor(i);
    ptrs.clear();
    for (VariableId v : fac.variables()) ptrs.push_back(&g.values()[static_cast<size_t>(g.offset(v))]);
    const int m = fac.residual_dim();
    e.resize(m);
    L.resize(m, m);
    fac.evaluate(ptrs.data(), e.data(), nullptr);
    fac.sqrt_information_at(ptrs.data(), L.data());
    r = L.triangularView<Eigen::Upper>() * e;
    total += f(i, r.squaredNorm());
  }
  return total;
}

}  // namespace

double FactorGraph::chi2() const {
  return sum_over_factors(*this, [](int, double s) { return s; });
}

int FactorGraph::first_nonfinite_factor() const {
  int first = -1;
  sum_over_factors(*this, [&first](int i, double s) {
    if (first < 0 && !std::isfinite(s)) first = i;
    return 0.0;
  });
  return first;
}

double FactorGraph::robust_cost() const {
  return sum_over_factors(*this, [this](int i, double s) {
    const RobustKernel* k = robust_kernel(i);
    if (!k) return s;
    double rho[3];
    k->evaluate(s, rho);
    return rho[0];
  });
}

}  // namespace planarvo::graph
