#include "graph/solver/robust_kernel.h"

#include <cmath>
#include <sstream>

#include "core/error.h"

namespace planarvo::graph {
namespace {

double check_scale(const char* kernel, double v) {
  if (!(v > 0.0) || !std::isfinite(v))
    throw_invalid_argument(std::string(kernel) + " kernel: the scale must be positive and finite");
  return v;
}

std::string named(const char* kernel, double v) {
  std::ostringstream s;
  s << kernel << "(" << v << ")";
  return s.str();
}

}  // namespace

HuberKernel::HuberKernel(double delta)
    : delta_(check_scale("Huber", delta)), delta2_(delta * delta) {}

void HuberKernel::evaluate(double s, double rho[3]) const {
  if (s <= delta2_) {
    rho[0] = s;
    rho[1] = 1.0;
    rho[2] = 0.0;
  } else {
    const double r = std::sqrt(s);
    rho[0] = 2.0 * delta_ * r - delta2_;
    rho[1] = delta_ / r;
    rho[2] = -0.5 * rho[1] / s;
  }
}

std::string HuberKernel::name() const { return named("Huber", delta_); }

CauchyKernel::CauchyKernel(double c) : c_(check_scale("Cauchy", c)), c2_(c * c) {}

void CauchyKernel::evaluate(double s, double rho[3]) const {
  const double inv = 1.0 / c2_;
  const double a = 1.0 + s * inv;
  rho[0] = c2_ * std::log1p(s * inv);
  rho[1] = 1.0 / a;
  rho[2] = -inv * rho[1] * rho[1];
}

std::string CauchyKernel::name() const { return named("Cauchy", c_); }

TukeyKernel::TukeyKernel(double c) : c_(check_scale("Tukey", c)), c2_(c * c) {}

void TukeyKernel::evaluate(double s, double rho[3]) const {
  if (s <= c2_) {
    const double a = 1.0 - s / c2_;
    rho[0] = c2_ / 3.0 * (1.0 - a * a * a);
    rho[1] = a * a;
    rho[2] = -2.0 * a / c2_;
  } else {
    rho[0] = c2_ / 3.0;
    rho[1] = 0.0;
    rho[2] = 0.0;
  }
}

std::string TukeyKernel::name() const { return named("Tukey", c_); }

}  // namespace planarvo::graph
