#include "track/readout_twist.h"

namespace planarvo::track {

Eigen::Vector3d ReadoutTwist::extrapolate(double at, const Eigen::Vector3d* c, double tc) const {
  // The newest two of (c_[1], c_[0], c).
  const Eigen::Vector3d* b = c ? c : (n_ >= 1 ? &c_[0] : nullptr);
  const double tb = c ? tc : t_[0];
  const Eigen::Vector3d* a = c ? (n_ >= 1 ? &c_[0] : nullptr) : (n_ >= 2 ? &c_[1] : nullptr);
  const double ta = c ? t_[0] : t_[1];
  if (!b) return Eigen::Vector3d::Zero();
  if (!a || !(tb - ta > 1e-6)) return *b;
  return *b + (*b - *a) * ((at - tb) / (tb - ta));
}

Eigen::Vector3d ReadoutTwist::predict(double t) const { return extrapolate(t + m_, nullptr, 0.0); }

Eigen::Vector3d ReadoutTwist::measure(double t, double dt, const Eigen::Vector3d& v, const Eigen::Vector3d& own,
                                      Eigen::Vector3d* c, double* tc) const {
  const double k = m_ / dt;
  *c = (v + k * own) / (1.0 + k);
  *tc = ((t - 0.5 * dt) + k * (t + m_)) / (1.0 + k);
  return extrapolate(t + m_, c, *tc);
}

void ReadoutTwist::commit(const Eigen::Vector3d& c, double tc) {
  c_[1] = c_[0];
  t_[1] = t_[0];
  c_[0] = c;
  t_[0] = tc;
  if (n_ < 2) ++n_;
}

}  // namespace planarvo::track
