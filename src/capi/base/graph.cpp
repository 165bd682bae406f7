// C API: pose graphs, motion pairs and the graph calibrations (src/graph, src/io/motions.h).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "capi/convert.h"
#include "capi/graph_convert.h"
#include "capi/status.h"
#include "core/sensor_motion.h"
#include "core/error.h"
#include "graph/calibration/calibration.h"
#include "graph/posegraph/optimize.h"
#include "graph/solver/solver.h"
#include "io/motions.h"

using planarvo::capi::guard;
using planarvo::capi::require;

namespace {

void send_lines(planarvo_log_fn log, void* user, const std::string& text) {
  if (!log) return;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) log(user, line.c_str());
}

void fill_summary(const planarvo::graph::SolverSummary& s, double initial_chi2, double final_chi2,
                  planarvo_solver_summary* out) {
  planarvo_solver_summary o;
  std::memset(&o, 0, sizeof o);
  o.converged = s.converged() ? 1 : 0;
  planarvo::capi::copy_string(o.termination, sizeof o.termination, s.message.empty() ? to_string(s.termination) : s.message);
  o.iterations = s.num_iterations;
  o.factorizations = s.num_factorizations;
  o.initial_chi2 = initial_chi2;
  o.final_chi2 = final_chi2;
  o.seconds = s.total_time_s;
  planarvo::capi::write_versioned(o, out);
}

constexpr size_t kSummaryEnd = offsetof(planarvo_solver_summary, seconds) + sizeof(double);
// The first versioned planarvo_motion_pair ended with direction; the covariances came after.
constexpr size_t kMotionPairEnd = offsetof(planarvo_motion_pair, direction) + sizeof(int32_t);

constexpr size_t kCalibrationResultEnd =
    offsetof(planarvo_calibration_result, summary) + sizeof(planarvo_solver_summary);

planarvo_robust_loss to_c(planarvo::graph::RobustLoss l) {
  switch (l) {
    case planarvo::graph::RobustLoss::None: return PLANARVO_ROBUST_LOSS_NONE;
    case planarvo::graph::RobustLoss::Huber: return PLANARVO_ROBUST_LOSS_HUBER;
    case planarvo::graph::RobustLoss::Cauchy: return PLANARVO_ROBUST_LOSS_CAUCHY;
    case planarvo::graph::RobustLoss::Tukey: return PLANARVO_ROBUST_LOSS_TUKEY;
  }
  return PLANARVO_ROBUST_LOSS_CAUCHY;
}
planarvo::graph::RobustLoss to_cpp(const planarvo_robust_loss& loss) {
  switch (planarvo::capi::enum_value(loss)) {
    case PLANARVO_ROBUST_LOSS_NONE: return planarvo::graph::RobustLoss::None;
    case PLANARVO_ROBUST_LOSS_HUBER: return planarvo::graph::RobustLoss::Huber;
    case PLANARVO_ROBUST_LOSS_CAUCHY: return planarvo::graph::RobustLoss::Cauchy;
    case PLANARVO_ROBUST_LOSS_TUKEY: return planarvo::graph::RobustLoss::Tukey;
  }
  planarvo::throw_invalid_argument("planarvo_calibration_options.loss is not a planarvo_robust_loss");
}

// The noise-model options in the header's words (graph::calibrate checks the same, in its own).
void validate_noise_model(const planarvo_calibration_options& o) {
  auto non_negative = [](double v, const char* name) {
    if (!(std::isfinite(v) && v >= 0.0))
      planarvo::throw_invalid_argument(std::string("planarvo_calibration_options.") + name +
                                       " must be >= 0 and finite");
  };
  auto positive = [](double v, const char* name) {
    if (!(std::isfinite(v) && v > 0.0))
      planarvo::throw_invalid_argument(std::string("planarvo_calibration_options.") + name +
                                       " must be > 0 and finite");
  };
  non_negative(o.sensor_sigma_relative, "sensor_sigma_relative");
  non_negative(o.sensor_sigma_floor, "sensor_sigma_floor");
  positive(o.sensor_sigma_theta, "sensor_sigma_theta");
  non_negative(o.odometry_sigma_relative, "odometry_sigma_relative");
  non_negative(o.odometry_sigma_floor, "odometry_sigma_floor");
  positive(o.odometry_sigma_theta, "odometry_sigma_theta");
  if (o.sensor_sigma_floor == 0.0 && o.sensor_sigma_relative == 0.0)
    planarvo::throw_invalid_argument("planarvo_calibration_options.sensor_sigma_floor and sensor_sigma_relative are "
                                     "both 0: a translation's standard deviation would be 0");
  if (o.odometry_sigma_floor == 0.0 && o.odometry_sigma_relative == 0.0)
    planarvo::throw_invalid_argument("planarvo_calibration_options.odometry_sigma_floor and odometry_sigma_relative "
                                     "are both 0: a translation's standard deviation would be 0");
  (void)to_cpp(o.loss);  // throws for a value that is not a planarvo_robust_loss
  positive(o.loss_scale, "loss_scale");
  non_negative(o.gate_sigma, "gate_sigma");
  non_negative(o.still_speed, "still_speed");
}

// Element i of a caller's array of planarvo_motion_pair, whose stride is its struct_size.
const void* element(const planarvo_motion_pair* pairs, size_t stride, size_t i) {
  return reinterpret_cast<const unsigned char*>(pairs) + i * stride;
}
void* element(planarvo_motion_pair* pairs, size_t stride, size_t i) {
  return reinterpret_cast<unsigned char*>(pairs) + i * stride;
}

// The array's stride, pairs[0].struct_size, checked against the first version's size.
size_t motion_pair_stride(const planarvo_motion_pair* pairs) {
  size_t stride = 0;
  std::memcpy(&stride, pairs, sizeof stride);
  planarvo::capi::require_struct_size(stride, kMotionPairEnd, "planarvo_motion_pair");
  return stride;
}

// Pair i of the caller's array as a sample: fields beyond its struct_size take their defaults.
// Each pair's residual at the estimate and whether it was gated out (planarvo_pair_residual).
void residuals_to_c(const planarvo::graph::CalibrationResult& r, size_t count, planarvo_pair_residual* out) {
  std::vector<char> outlier(count, 0);
  for (int k : r.outlier_samples) outlier.at(static_cast<size_t>(k)) = 1;
  for (size_t i = 0; i < count; ++i) {
    planarvo_pair_residual o;
    std::memset(&o, 0, sizeof o);
    o.outlier = outlier[i];
    if (i < r.residuals.size() && r.residuals[i]) {
      const planarvo::graph::PairResidual& p = *r.residuals[i];
      o.has_odometry = 1;
      for (int k = 0; k < 3; ++k) o.d[k] = p.d[k];
      planarvo::capi::matrix_to_c<3>(p.covariance, o.covariance);
      o.chi2 = p.chi2;
    }
    out[i] = o;
  }
}

void odometry_noise_to_c(const planarvo::graph::CalibrationResult& r, planarvo_odometry_noise* out) {
  planarvo_odometry_noise o;
  std::memset(&o, 0, sizeof o);
  if (r.odometry_noise) {
    o.fitted = 1;
    for (int c = 0; c < 3; ++c) {
      o.variance[c * 3 + 0] = r.odometry_noise->constant[c];
      o.variance[c * 3 + 1] = r.odometry_noise->per_translation[c];
      o.variance[c * 3 + 2] = r.odometry_noise->per_rotation[c];
    }
  }
  *out = o;
}

planarvo::graph::MotionSample read_pair(const planarvo_motion_pair* pairs, size_t stride, size_t i) {
  planarvo_motion_pair p;
  planarvo_motion_pair_init(&p);
  std::memcpy(static_cast<void*>(&p), element(pairs, stride, i), std::min(stride, sizeof p));
  const std::string where = "planarvo_calibrate: pairs[" + std::to_string(i) + "]";
  if (p.struct_size != stride)
    planarvo::throw_invalid_argument(where + ".struct_size is " + std::to_string(p.struct_size) + ", pairs[0]'s " +
                                     std::to_string(stride) + ": every element needs the same (planarvo_motion_pair_init)");
  auto require_covariance = [&](int32_t has, const double* c, const char* name) {
    if (!has) return;
    bool zero = true;
    for (int k = 0; k < 9; ++k) {
      if (!std::isfinite(c[k])) planarvo::throw_invalid_argument(where + "." + name + " is not finite");
      zero = zero && c[k] == 0.0;
    }
    if (zero)
      planarvo::throw_invalid_argument(where + "." + name + " is zero: clear has_" + name +
                                       " to use the options' noise model");
  };
  require_covariance(p.has_sensor_covariance, p.sensor_covariance, "sensor_covariance");
  require_covariance(p.has_odometry_covariance, p.odometry_covariance, "odometry_covariance");
  if (p.has_odometry_covariance && !p.has_odometry)
    planarvo::throw_invalid_argument(where + " has an odometry_covariance but no odometry");
  planarvo::graph::MotionSample s;
  s.interval = p.interval;
  s.sensor = planarvo::capi::motion_from_c(p.sensor, p.has_sensor_covariance, p.sensor_covariance);
  if (p.has_odometry)
    s.odometry = planarvo::capi::motion_from_c(p.odometry, p.has_odometry_covariance, p.odometry_covariance);
  if (p.has_direction) {
    if (p.direction < -1 || p.direction > 1)
      planarvo::throw_invalid_argument(where + ".direction is " + std::to_string(p.direction) +
                                       ", not -1, 0 or +1");
    s.direction = p.direction;
  }
  return s;
}

}  // namespace

namespace planarvo::capi {

planarvo::graph::CalibrationOptions calibration_options_from_c(const planarvo_calibration_options* options,
                                                               planarvo_calibration_options* read,
                                                               bool estimate_odometry_noise) {
  planarvo_calibration_options& o = *read;
  planarvo_calibration_options_init(&o);
  if (options) {
    planarvo::capi::require_struct_size(options->struct_size,
                                        offsetof(planarvo_calibration_options, log_user_data) + sizeof(void*),
                                        "planarvo_calibration_options");
    o = planarvo::capi::read_versioned(*options, o);
  }
  const int method = planarvo::capi::enum_value(o.method);
  require(method == PLANARVO_CALIBRATE_ODOMETRY || method == PLANARVO_CALIBRATE_NONHOLONOMIC,
          "planarvo_calibration_options.method is not a planarvo_calibration_method");
  require(o.max_iterations > 0, "planarvo_calibration_options.max_iterations must be positive");
  require(!o.fix_scale || (std::isfinite(o.fixed_scale) && o.fixed_scale > 0),
          "planarvo_calibration_options.fixed_scale must be positive");
  validate_noise_model(o);
  planarvo::graph::CalibrationOptions co;
  co.method = o.method == PLANARVO_CALIBRATE_ODOMETRY ? planarvo::graph::CalibrationMethod::Odometry
                                                      : planarvo::graph::CalibrationMethod::Nonholonomic;
  co.fix_scale = o.fix_scale != 0;
  co.fixed_scale = o.fixed_scale;
  if (o.has_initial) co.initial = std::array<double, 4>{o.initial[0], o.initial[1], o.initial[2], o.initial[3]};
  co.nonholonomic_form = o.velocity_form ? planarvo::graph::CalibrationOptions::NonholonomicForm::Velocity
                                         : planarvo::graph::CalibrationOptions::NonholonomicForm::Arc;
  co.solver.max_iterations = o.max_iterations;
  co.sensor_sigma_relative = o.sensor_sigma_relative;
  co.sensor_sigma_floor = o.sensor_sigma_floor;
  co.sensor_sigma_theta = o.sensor_sigma_theta;
  co.odometry_sigma_relative = o.odometry_sigma_relative;
  co.odometry_sigma_floor = o.odometry_sigma_floor;
  co.odometry_sigma_theta = o.odometry_sigma_theta;
  co.loss = ::to_cpp(o.loss);
  co.loss_scale = o.loss_scale;
  co.gate_sigma = o.gate_sigma;
  co.still_speed = o.still_speed;
  co.estimate_odometry_noise = o.estimate_odometry_noise < 0 ? estimate_odometry_noise : o.estimate_odometry_noise > 0;
  return co;
}

planarvo_calibration_result calibration_result_to_c(const planarvo::graph::CalibrationResult& r) {
  planarvo_calibration_result out;
  std::memset(&out, 0, sizeof out);
  for (int i = 0; i < 4; ++i) {
    out.value[i] = r.value[static_cast<size_t>(i)];
    out.estimated[i] = r.estimated[static_cast<size_t>(i)];
    out.observable[i] = r.observable[static_cast<size_t>(i)];
  }
  planarvo::capi::matrix_to_c<4>(r.covariance, out.covariance);
  out.ambiguous = r.ambiguous;
  out.outliers = r.outliers;
  out.ok = r.ok();
  planarvo::capi::copy_string(out.unobservable_reason, sizeof out.unobservable_reason, r.unobservable_reason);
  out.summary.struct_size = sizeof out.summary;
  // The solver's cost is already the sum of e' Omega e (graph/normal_equations_assembly.cpp).
  fill_summary(r.summary, r.summary.initial_cost, r.summary.final_cost, &out.summary);
  out.total_iterations = r.total_iterations;
  out.total_seconds = r.total_time_s;
  out.variance_factor = r.variance_factor;
  return out;
}

}  // namespace planarvo::capi

extern "C" {

PLANARVO_API planarvo_status planarvo_sensor_motion(const planarvo_extrinsics* e, const planarvo_se2* robot_motion,
                                                   const double* robot_covariance, planarvo_se2* sensor_motion,
                                                   double* sensor_covariance) {
  return guard([&] {
    require(e != nullptr && robot_motion != nullptr && sensor_motion != nullptr,
            "planarvo_sensor_motion: NULL argument");
    planarvo::Motion m;
    m.value = planarvo::capi::to_cpp(*robot_motion);
    if (robot_covariance) m.covariance = planarvo::capi::matrix_from_c<3>(robot_covariance);
    const planarvo::Motion s = planarvo::sensor_motion(planarvo::capi::to_cpp(*e), m);
    *sensor_motion = planarvo::capi::to_c(s.value);
    if (sensor_covariance) planarvo::capi::matrix_to_c<3>(s.covariance, sensor_covariance);
  });
}

PLANARVO_API void planarvo_posegraph_options_init(planarvo_posegraph_options* o) {
  if (!o) return;
  std::memset(o, 0, sizeof *o);
  o->struct_size = sizeof *o;
  o->max_iterations = planarvo::graph::SolverOptions().max_iterations;
  o->init = PLANARVO_POSEGRAPH_INIT_NONE;
}

PLANARVO_API planarvo_status planarvo_posegraph_optimize(const char* in_path, const char* out_path,
                                                         const planarvo_posegraph_options* options,
                                                         planarvo_solver_summary* summary) {
  bool converged = true;
  std::string why;
  const planarvo_status st = guard([&] {
    require(in_path != nullptr && *in_path, "planarvo_posegraph_optimize: in_path is NULL or empty");
    require(summary != nullptr, "planarvo_posegraph_optimize: summary is NULL");
    planarvo::capi::require_struct_size(summary->struct_size, kSummaryEnd, "planarvo_solver_summary");
    planarvo_posegraph_options o;
    planarvo_posegraph_options_init(&o);
    if (options) {
      planarvo::capi::require_struct_size(options->struct_size,
                                          offsetof(planarvo_posegraph_options, log_user_data) + sizeof(void*),
                                          "planarvo_posegraph_options");
      o = planarvo::capi::read_versioned(*options, o);
    }
    const int init = planarvo::capi::enum_value(o.init);
    require(init == PLANARVO_POSEGRAPH_INIT_NONE || init == PLANARVO_POSEGRAPH_INIT_ROTATION_FIRST,
            "planarvo_posegraph_options.init is not a planarvo_posegraph_init");
    planarvo::graph::PosegraphOptions po;
    po.max_iterations = o.max_iterations;
    po.rotation_first = o.init == PLANARVO_POSEGRAPH_INIT_ROTATION_FIRST;
    if (o.log) po.log = [&o](const std::string& report) { send_lines(o.log, o.log_user_data, report); };
    const planarvo::graph::PosegraphResult r =
        planarvo::graph::optimize_g2o(in_path, out_path ? out_path : "", po);
    const planarvo::graph::SolverSummary& s = r.summary;
    fill_summary(s, r.initial_chi2, r.final_chi2, summary);
    converged = s.converged();
    why = summary->termination;
  });
  if (st == PLANARVO_OK && !converged) return planarvo::capi::fail(PLANARVO_ERROR_FAILED, "did not converge: " + why);
  return st;
}

PLANARVO_API planarvo_status planarvo_motion_pairs_load(const char* path, planarvo_motion_pair* pairs,
                                                        size_t capacity, size_t* count) {
  return guard([&] {
    require(path != nullptr && *path, "planarvo_motion_pairs_load: path is NULL or empty");
    require(count != nullptr, "planarvo_motion_pairs_load: count is NULL");
    const planarvo::io::MotionPairs m = planarvo::io::read_motion_pairs(path);
    *count = m.pairs.size();
    if (!pairs) return;
    if (capacity < m.pairs.size())
      throw planarvo::capi::BufferTooSmall("planarvo_motion_pairs_load: " + std::to_string(m.pairs.size()) +
                                           " pairs, capacity " + std::to_string(capacity));
    const size_t stride = motion_pair_stride(pairs);
    for (size_t i = 0; i < m.pairs.size(); ++i) {
      const planarvo::io::MotionPair& p = m.pairs[i];
      planarvo_motion_pair o;
      planarvo_motion_pair_init(&o);
      o.struct_size = stride;
      o.interval = p.interval;
      planarvo::capi::motion_to_c(p.sensor, &o.sensor, &o.has_sensor_covariance, o.sensor_covariance);
      o.has_odometry = p.odometry.has_value();
      if (p.odometry)
        planarvo::capi::motion_to_c(*p.odometry, &o.odometry, &o.has_odometry_covariance, o.odometry_covariance);
      o.has_direction = p.direction.has_value();
      if (p.direction) o.direction = *p.direction;
      std::memcpy(element(pairs, stride, i), &o, std::min(stride, sizeof o));
    }
  });
}

PLANARVO_API planarvo_status planarvo_motion_pairs_save(const char* path, const planarvo_motion_pair* pairs,
                                                        size_t count) {
  return guard([&] {
    require(path != nullptr && *path, "planarvo_motion_pairs_save: path is NULL or empty");
    require(count == 0 || pairs != nullptr, "planarvo_motion_pairs_save: pairs is NULL");
    std::vector<planarvo::io::MotionPair> out(count);
    const size_t stride = count > 0 ? motion_pair_stride(pairs) : sizeof(planarvo_motion_pair);
    for (size_t i = 0; i < count; ++i) {
      const planarvo::graph::MotionSample s = read_pair(pairs, stride, i);
      out[i].interval = s.interval;
      out[i].sensor = s.sensor;
      out[i].odometry = s.odometry;
      out[i].direction = s.direction;
    }
    planarvo::io::write_motion_pairs(path, out);
  });
}

PLANARVO_API void planarvo_motion_pair_init(planarvo_motion_pair* pair) {
  if (!pair) return;
  std::memset(pair, 0, sizeof *pair);
  pair->struct_size = sizeof *pair;
}

PLANARVO_API void planarvo_calibration_options_init(planarvo_calibration_options* o) {
  if (!o) return;
  std::memset(o, 0, sizeof *o);
  const planarvo::graph::CalibrationOptions d;
  o->struct_size = sizeof *o;
  o->method = PLANARVO_CALIBRATE_ODOMETRY;
  o->fix_scale = d.fix_scale ? 1 : 0;
  o->fixed_scale = d.fixed_scale;
  o->velocity_form = 0;
  o->max_iterations = d.solver.max_iterations;
  o->sensor_sigma_relative = d.sensor_sigma_relative;
  o->sensor_sigma_floor = d.sensor_sigma_floor;
  o->sensor_sigma_theta = d.sensor_sigma_theta;
  o->odometry_sigma_relative = d.odometry_sigma_relative;
  o->odometry_sigma_floor = d.odometry_sigma_floor;
  o->odometry_sigma_theta = d.odometry_sigma_theta;
  o->loss = to_c(d.loss);
  o->loss_scale = d.loss_scale;
  o->gate_sigma = d.gate_sigma;
  o->still_speed = d.still_speed;
  o->estimate_odometry_noise = -1;  // the workflow's choice (calibration_options_from_c)
}

PLANARVO_API planarvo_status planarvo_calibrate(const planarvo_motion_pair* pairs, size_t count,
                                                const planarvo_calibration_options* options,
                                                planarvo_calibration_result* result) {
  return planarvo_calibrate_residuals(pairs, count, options, result, nullptr, nullptr);
}

PLANARVO_API planarvo_status planarvo_calibrate_residuals(const planarvo_motion_pair* pairs, size_t count,
                                                          const planarvo_calibration_options* options,
                                                          planarvo_calibration_result* result,
                                                          planarvo_pair_residual* residuals,
                                                          planarvo_odometry_noise* noise) {
  bool ok = true;
  std::string reason;
  const planarvo_status st = guard([&] {
    require(result != nullptr, "planarvo_calibrate: result is NULL");
    planarvo::capi::require_struct_size(result->struct_size, kCalibrationResultEnd, "planarvo_calibration_result");
    require(count > 0 && pairs != nullptr, "planarvo_calibrate: no motion pairs");
    planarvo_calibration_options o;
    const planarvo::graph::CalibrationOptions co = planarvo::capi::calibration_options_from_c(options, &o, false);
    const size_t stride = motion_pair_stride(pairs);
    std::vector<planarvo::graph::MotionSample> samples;
    samples.reserve(count);
    for (size_t i = 0; i < count; ++i) samples.push_back(read_pair(pairs, stride, i));
    const planarvo::graph::CalibrationResult r = planarvo::graph::calibrate(samples, co);
    send_lines(o.log, o.log_user_data, r.summary.full_report());
    const planarvo_calibration_result out = planarvo::capi::calibration_result_to_c(r);
    planarvo::capi::write_versioned(out, result);
    if (residuals) residuals_to_c(r, count, residuals);
    if (noise) odometry_noise_to_c(r, noise);
    ok = r.ok();
    reason = r.ambiguous ? std::string("ambiguous: (x, yaw) and (-x, yaw + 180 deg) fit equally; give direction "
                                       "labels or odometry")
             : !r.unobservable_reason.empty() ? r.unobservable_reason
                                              : "did not converge: " + std::string(out.summary.termination);
  });
  if (st == PLANARVO_OK && !ok) return planarvo::capi::fail(PLANARVO_ERROR_FAILED, reason);
  return st;
}

}  // extern "C"
