#include "node_params.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <ros/ros.h>

namespace planarvo_node {
namespace {

// The private namespace, remembering every parameter asked for: what the node knows, so that any
// other one there is refused (no_unknown_params) without a second list of the names.
struct Reader {
  const ros::NodeHandle& nh;
  std::vector<std::string> asked;
  bool getParam(const std::string& name, XmlRpc::XmlRpcValue& v) {
    asked.push_back(name);
    return nh.getParam(name, v);
  }
};

// A parameter's value as a user wrote it ("12", "true", "abc"), for the error messages.
std::string text(XmlRpc::XmlRpcValue& v) {
  std::ostringstream os;
  os << v;
  return v.getType() == XmlRpc::XmlRpcValue::TypeString ? "\"" + os.str() + "\"" : os.str();
}

// A string parameter that a user may also give as a number (~device:=1 arrives as an int).
bool get_text(Reader& nh, const std::string& name, std::string* out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return true;
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeString: *out = static_cast<std::string>(v); return true;
    case XmlRpc::XmlRpcValue::TypeInt: *out = std::to_string(static_cast<int>(v)); return true;
    default:
      ROS_FATAL("planarvo_node: parameter ~%s must be a string, not %s", name.c_str(), text(v).c_str());
      return false;
  }
}

bool get_int(Reader& nh, const std::string& name, int lo, int hi, int* out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return true;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeInt || static_cast<int>(v) < lo || static_cast<int>(v) > hi) {
    ROS_FATAL("planarvo_node: parameter ~%s must be an integer within %d..%d, not %s", name.c_str(), lo, hi,
              text(v).c_str());
    return false;
  }
  *out = static_cast<int>(v);
  return true;
}

bool get_double(Reader& nh, const std::string& name, double lo, double hi, double* out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return true;
  double x = NAN;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) x = static_cast<double>(v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) x = static_cast<int>(v);
  if (!(x >= lo && x <= hi)) {
    ROS_FATAL("planarvo_node: parameter ~%s must be a number within %g..%g, not %s", name.c_str(), lo, hi,
              text(v).c_str());
    return false;
  }
  *out = x;
  return true;
}

bool get_bool(Reader& nh, const std::string& name, bool* out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return true;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeBoolean) {
    ROS_FATAL("planarvo_node: parameter ~%s must be true or false, not %s", name.c_str(), text(v).c_str());
    return false;
  }
  *out = static_cast<bool>(v);
  return true;
}

bool get_frame(Reader& nh, const std::string& name, std::string* out) {
  if (!get_text(nh, name, out)) return false;
  if (out->empty() || out->find(' ') != std::string::npos) {
    ROS_FATAL("planarvo_node: parameter ~%s must be a frame name without spaces, not \"%s\"", name.c_str(),
              out->c_str());
    return false;
  }
  return true;
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// A private parameter the node does not read is a misspelt one (~publish_tfs for ~publish_tf):
// ROS_FATAL naming it and the nearest of those the node asked for.
bool no_unknown_params(const Reader& r) {
  std::vector<std::string> names;
  if (!r.nh.getParamNames(names)) return true;
  const std::string prefix = r.nh.getNamespace() + "/";
  for (const std::string& full : names) {
    if (full.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string name = full.substr(prefix.size(), full.find('/', prefix.size()) - prefix.size());
    if (std::find(r.asked.begin(), r.asked.end(), name) != r.asked.end()) continue;
    const auto nearest = std::min_element(
        r.asked.begin(), r.asked.end(),
        [&](const std::string& a, const std::string& b) { return edit_distance(name, a) < edit_distance(name, b); });
    ROS_FATAL("planarvo_node: unknown parameter ~%s (did you mean ~%s? ros/README.md lists the parameters)",
              name.c_str(), nearest == r.asked.end() ? "" : nearest->c_str());
    return false;
  }
  return true;
}

}  // namespace

bool read_params(const ros::NodeHandle& private_nh, NodeParams* p) {
  Reader nh{private_nh, {}};
  planarvo_tracker_options_init(&p->tracker);
  planarvo_tracker_options& t = p->tracker;
  int levels = t.levels, finest = t.finest_level, subsample = t.level0_subsample, iterations = t.max_iterations;
  bool local_plane = t.local_plane != 0;
  double plane_prior_deg = t.local_plane_prior_sigma * 180.0 / M_PI;
  double mounting_step_deg = t.mounting_min_step * 180.0 / M_PI;
  std::string mounting_change = "recalibrate";
  bool ok = get_text(nh, "camera", &p->camera) && get_text(nh, "extrinsics", &p->extrinsics) &&
            get_text(nh, "device", &p->device) && get_text(nh, "cache_dir", &p->cache_dir) &&
            get_text(nh, "kernel_binaries", &p->kernel_binaries) &&
            get_bool(nh, "prepare_kernels", &p->prepare_kernels) && get_frame(nh, "odom_frame", &p->odom_frame) &&
            get_frame(nh, "base_frame", &p->base_frame) && get_bool(nh, "publish_tf", &p->publish_tf) &&
            get_int(nh, "levels", 1, 8, &levels) && get_int(nh, "finest_level", -1, levels - 1, &finest) &&
            get_int(nh, "level0_subsample", 0, 8, &subsample) && get_text(nh, "flat_field", &p->flat_field) &&
            get_double(nh, "readout_time", -1.0, 1.0, &p->readout_time) &&
            get_double(nh, "exposure_time", -1.0, 1.0, &p->exposure_time) &&
            get_int(nh, "max_iterations", 0, 1000, &iterations) && get_bool(nh, "local_plane", &local_plane) &&
            get_double(nh, "local_plane_prior_deg", 1e-6, 90.0, &plane_prior_deg) &&
            get_text(nh, "mounting_change", &mounting_change) &&
            get_double(nh, "mounting_step_deg", 1e-3, 45.0, &mounting_step_deg) &&
            get_double(nh, "keyframe_overlap", 0.0, 1.0, &t.keyframe_overlap) &&
            get_int(nh, "queue_size", 1, 100000, &p->queue_size) &&
            get_int(nh, "max_pending", 1, 100000, &p->max_pending) &&
            get_double(nh, "drain_seconds", 0.0, 3600.0, &p->drain_seconds) &&
            get_bool(nh, "calibrate", &p->calibrate) &&
            get_text(nh, "calibration_output", &p->calibration_output) &&
            get_int(nh, "calibration_frames", 0, 10000000, &p->calibration_frames) &&
            get_double(nh, "calibration_height", 0.0, 100.0, &p->calibration_height) &&
            get_double(nh, "calibration_odom_wait", 0.0, 60.0, &p->calibration_odom_wait) &&
            get_bool(nh, "force", &p->force);
  if (!ok || !no_unknown_params(nh)) return false;
  t.levels = levels;
  t.finest_level = finest;
  t.level0_subsample = subsample;
  t.max_iterations = iterations;
  t.accept_unusual_extrinsics = p->force ? 1 : 0;
  t.local_plane = local_plane ? 1 : 0;
  t.local_plane_prior_sigma = plane_prior_deg * M_PI / 180.0;
  t.mounting_min_step = mounting_step_deg * M_PI / 180.0;
  if (mounting_change == "recalibrate") t.on_mounting_change = PLANARVO_MOUNTING_RECALIBRATE;
  else if (mounting_change == "report") t.on_mounting_change = PLANARVO_MOUNTING_REPORT;
  else if (mounting_change == "ignore") t.on_mounting_change = PLANARVO_MOUNTING_IGNORE;
  else {
    ROS_FATAL("planarvo_node: ~mounting_change must be recalibrate, report or ignore, not \"%s\"",
              mounting_change.c_str());
    return false;
  }
  if (p->calibrate && p->calibration_output.empty()) {
    ROS_FATAL("planarvo_node: ~calibrate is true but ~calibration_output (the extrinsics file to write) is not set");
    return false;
  }
  if (!p->calibrate && p->extrinsics.empty()) {
    ROS_FATAL("planarvo_node: ~extrinsics (the camera's extrinsics.yaml) is required for tracking; or set "
              "~calibrate true and ~calibration_output FILE to calibrate them from the images and /odom");
    return false;
  }
  return true;
}

}  // namespace planarvo_node
