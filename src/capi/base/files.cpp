// C API: the files the base library writes and reads without OpenCV: camera.yaml and
// extrinsics.yaml written (io/yaml_writer.h), TUM trajectories, plane.txt, the statistics CSV.
// Reading the YAML files needs cv::FileStorage: vision/files_yaml.cpp.
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>

#include "capi/convert.h"
#include "capi/status.h"
#include "core/error.h"
#include "core/extrinsics_estimate.h"
#include "graph/calibration/calibration_extrinsics.h"
#include "io/formats.h"
#include "io/stats.h"

using planarvo::capi::guard;
using planarvo::capi::require;

using planarvo::capi::require_path;

namespace {

// The readers' "ask, then fill" convention: *count (when not NULL) receives the file's entries;
// with capacity 0 nothing else happens; a capacity short of them is InvalidArgument, writing
// nothing; else put(i, entry) writes each.
template <class T, class Put>
void copy_out(const std::vector<T>& entries, size_t capacity, size_t* count, const char* fn, const char* path,
              const char* what, Put&& put) {
  if (count) *count = entries.size();
  if (capacity == 0) return;
  if (capacity < entries.size())
    planarvo::throw_invalid_argument(std::string(fn) + ": " + path + " has " + std::to_string(entries.size()) + " " +
                                     what + ", the arrays hold " + std::to_string(capacity));
  for (size_t i = 0; i < entries.size(); ++i) put(i, entries[i]);
}

}  // namespace

extern "C" {

PLANARVO_API planarvo_status planarvo_camera_save(const char* path, const planarvo_camera* camera) {
  return guard([&] {
    require_path(path, "planarvo_camera_save");
    require(camera != nullptr, "planarvo_camera_save: camera is NULL");
    const planarvo::CameraModel m = planarvo::capi::to_cpp(*camera);
    try {
      m.validate("planarvo_camera_save");
    } catch (const planarvo::Error& e) {
      throw planarvo::Error(planarvo::ErrorCode::InvalidArgument, e.what());
    }
    planarvo::io::write_camera_yaml(path, m);
  });
}

PLANARVO_API planarvo_status planarvo_extrinsics_save(const char* path, const planarvo_extrinsics* e,
                                                      const double* covariance, const char* estimated,
                                                      const char* method, const char* notes) {
  return guard([&] {
    require_path(path, "planarvo_extrinsics_save");
    require(e != nullptr, "planarvo_extrinsics_save: extrinsics is NULL");
    planarvo::ExtrinsicsEstimate f;
    f.value = planarvo::capi::to_cpp(*e);
    for (double v : {e->x, e->y, e->z, e->roll, e->pitch, e->yaw})
      require(std::isfinite(v), "planarvo_extrinsics_save: a value is NaN or inf");
    if (covariance) f.covariance = planarvo::capi::matrix_from_c<6>(covariance);
    if (estimated) {
      std::stringstream ss(estimated);
      std::string name;
      while (std::getline(ss, name, ',')) {
        if (name.empty()) continue;
        const int k = planarvo::extrinsics_index(name);
        require(k >= 0, ("planarvo_extrinsics_save: estimated names '" + name + "', not one of x y z roll pitch yaw").c_str());
        f.estimated[static_cast<size_t>(k)] = true;
      }
    }
    if (method) f.method = method;
    if (notes) f.notes = notes;
    planarvo::io::write_extrinsics_yaml(path, f);
  });
}

PLANARVO_API planarvo_status planarvo_camera_calibration_save(const char* path,
                                                              const planarvo_camera_calibration_result* result,
                                                              const char* notes) {
  return guard([&] {
    require_path(path, "planarvo_camera_calibration_save");
    require(result != nullptr, "planarvo_camera_calibration_save: result is NULL");
    planarvo::capi::require_struct_size(result->struct_size, sizeof *result, "planarvo_camera_calibration_result");
    planarvo::ExtrinsicsEstimate e;
    e.value = planarvo::capi::to_cpp(result->extrinsics);
    e.covariance = planarvo::capi::matrix_from_c<6>(result->covariance);
    for (size_t i = 0; i < 6; ++i) {
      e.estimated[i] = result->estimated[i] != 0;
      e.observable[i] = result->observable[i] != 0;
    }
    e.method.assign(result->method, strnlen(result->method, sizeof result->method));
    e.notes = notes ? notes : "";
    if (result->readout_evaluations > 0 && result->readout_reason[0] == 0) {
      char line[160];
      std::snprintf(line, sizeof line, "rolling_shutter_readout estimated %.6f s +- %.6f (%s)", result->readout_estimate,
                    result->readout_sigma, result->readout > 0 ? "used" : "taken as 0, a global shutter");
      e.notes += (e.notes.empty() ? "" : "; ") + std::string(line);
    }
    planarvo::io::write_extrinsics_yaml(path, e);
  });
}

PLANARVO_API planarvo_status planarvo_calibration_save(const char* path, const planarvo_calibration_result* result,
                                                       planarvo_calibration_method method, int32_t metric_sensor,
                                                       const char* notes) {
  return guard([&] {
    require_path(path, "planarvo_calibration_save");
    require(result != nullptr, "planarvo_calibration_save: result is NULL");
    const int m = planarvo::capi::enum_value(method);
    require(m == PLANARVO_CALIBRATE_ODOMETRY || m == PLANARVO_CALIBRATE_NONHOLONOMIC,
            "planarvo_calibration_save: method is not a planarvo_calibration_method");
    planarvo::capi::require_struct_size(result->struct_size, offsetof(planarvo_calibration_result, observable) +
                                                                 sizeof result->observable,
                                        "planarvo_calibration_result");
    planarvo::graph::CalibrationResult g;
    for (size_t i = 0; i < 4; ++i) {
      g.value[i] = result->value[i];
      g.estimated[i] = result->estimated[i] != 0;
      g.observable[i] = result->observable[i] != 0;
    }
    g.covariance = planarvo::capi::matrix_from_c<4>(result->covariance);
    const auto graph_method = m == PLANARVO_CALIBRATE_ODOMETRY ? planarvo::graph::CalibrationMethod::Odometry
                                                               : planarvo::graph::CalibrationMethod::Nonholonomic;
    planarvo::ExtrinsicsEstimate e = planarvo::graph::as_extrinsics(g, metric_sensor != 0);
    e.method = planarvo::graph::describe_method(graph_method);
    e.notes = notes ? notes : "";
    planarvo::io::write_extrinsics_yaml(path, e);
  });
}

PLANARVO_API planarvo_status planarvo_extrinsics_matrix(const planarvo_extrinsics* e, double matrix[16]) {
  return guard([&] {
    require(e != nullptr && matrix != nullptr, "planarvo_extrinsics_matrix: NULL argument");
    const Eigen::Matrix4d T = planarvo::capi::to_cpp(*e).T_vc();
    for (int i = 0; i < 16; ++i) matrix[i] = T(i / 4, i % 4);
  });
}

PLANARVO_API planarvo_status planarvo_read_tum(const char* path, double* timestamps, planarvo_se2* poses,
                                               size_t capacity, size_t* count) {
  return guard([&] {
    require_path(path, "planarvo_read_tum");
    require(capacity == 0 || (timestamps != nullptr && poses != nullptr), "planarvo_read_tum: NULL arrays");
    copy_out(planarvo::io::read_tum(path), capacity, count, "planarvo_read_tum", path, "poses",
             [&](size_t i, const planarvo::io::StampedPose& p) {
               timestamps[i] = p.t;
               poses[i] = planarvo::capi::to_c(p.pose);
             });
  });
}

PLANARVO_API planarvo_status planarvo_write_tum(const char* path, const double* timestamps,
                                                const planarvo_se2* poses, size_t count) {
  return guard([&] {
    require_path(path, "planarvo_write_tum");
    require(count == 0 || (timestamps != nullptr && poses != nullptr), "planarvo_write_tum: NULL arrays");
    std::vector<planarvo::io::StampedPose> v(count);
    for (size_t i = 0; i < count; ++i) v[i] = {timestamps[i], planarvo::capi::to_cpp(poses[i])};
    planarvo::io::write_tum(path, v);
  });
}

PLANARVO_API planarvo_status planarvo_read_plane(const char* path, planarvo_plane_attitude* rows, size_t capacity,
                                                 size_t* count) {
  return guard([&] {
    require_path(path, "planarvo_read_plane");
    require(capacity == 0 || rows != nullptr, "planarvo_read_plane: rows is NULL");
    copy_out(planarvo::io::read_plane(path), capacity, count, "planarvo_read_plane", path, "rows",
             [&](size_t i, const planarvo::io::PlaneAttitude& a) {
               rows[i] = {a.t, a.roll, a.pitch, a.sigma_roll, a.sigma_pitch};
             });
  });
}

PLANARVO_API planarvo_status planarvo_write_plane(const char* path, const planarvo_plane_attitude* rows, size_t count) {
  return guard([&] {
    require_path(path, "planarvo_write_plane");
    require(count == 0 || rows != nullptr, "planarvo_write_plane: rows is NULL");
    std::vector<planarvo::io::PlaneAttitude> v(count);
    for (size_t i = 0; i < count; ++i)
      v[i] = {rows[i].timestamp, rows[i].roll, rows[i].pitch, rows[i].sigma_roll, rows[i].sigma_pitch};
    planarvo::io::write_plane(path, v);
  });
}

struct planarvo_stats_writer {
  std::unique_ptr<planarvo::io::StatsWriter> writer;
};

PLANARVO_API planarvo_status planarvo_stats_writer_open(const char* path, planarvo_stats_writer** writer) {
  return guard([&] {
    require(writer != nullptr, "planarvo_stats_writer_open: writer is NULL");
    *writer = nullptr;
    require_path(path, "planarvo_stats_writer_open");
    auto w = std::make_unique<planarvo_stats_writer>();
    w->writer = std::make_unique<planarvo::io::StatsWriter>(path);
    *writer = w.release();
  });
}

PLANARVO_API planarvo_status planarvo_stats_writer_add(planarvo_stats_writer* writer, const planarvo_frame_stats* row) {
  return guard([&] {
    require(writer != nullptr && row != nullptr, "planarvo_stats_writer_add: NULL argument");
    planarvo::io::FrameStats r;
    r.timestamp = row->timestamp;
    r.vx = row->vx;
    r.vy = row->vy;
    r.omega = row->omega;
    r.iterations = row->iterations;
    r.final_cost = row->final_cost;
    r.inlier_fraction = row->inlier_fraction;
    r.ms = row->ms;
    r.status = row->status ? row->status : "";
    r.has_attitude = row->has_attitude != 0;
    r.roll = row->roll;
    r.pitch = row->pitch;
    r.sigma_roll = row->sigma_roll;
    r.sigma_pitch = row->sigma_pitch;
    r.mounting_changed = row->mounting_changed != 0;
    writer->writer->add(r);
  });
}

PLANARVO_API planarvo_status planarvo_stats_writer_close(planarvo_stats_writer* writer) {
  std::unique_ptr<planarvo_stats_writer> owned(writer);
  return guard([&] {
    if (owned) owned->writer->close();
  });
}

PLANARVO_API void planarvo_stats_writer_discard(planarvo_stats_writer* writer) {
  delete writer;  // the writer's destructor removes the partial file
}

struct planarvo_stats_table {
  std::vector<planarvo::io::FrameStats> rows;
};

PLANARVO_API planarvo_status planarvo_stats_read(const char* path, planarvo_stats_table** table) {
  return guard([&] {
    require(table != nullptr, "planarvo_stats_read: table is NULL");
    *table = nullptr;
    require_path(path, "planarvo_stats_read");
    auto t = std::make_unique<planarvo_stats_table>();
    t->rows = planarvo::io::read_stats(path);
    *table = t.release();
  });
}

PLANARVO_API size_t planarvo_stats_table_size(const planarvo_stats_table* table) {
  return table ? table->rows.size() : 0;
}

PLANARVO_API planarvo_status planarvo_stats_table_row(const planarvo_stats_table* table, size_t index,
                                                     planarvo_frame_stats* row) {
  return guard([&] {
    require(table != nullptr && row != nullptr, "planarvo_stats_table_row: NULL argument");
    require(index < table->rows.size(), ("planarvo_stats_table_row: index " + std::to_string(index) +
                                         " is past the table's " + std::to_string(table->rows.size()) + " rows")
                                            .c_str());
    const planarvo::io::FrameStats& r = table->rows[index];
    *row = {r.timestamp, r.vx, r.vy, r.omega, r.iterations, r.final_cost, r.inlier_fraction, r.ms,
            r.status.c_str(), r.has_attitude ? 1 : 0, r.roll, r.pitch, r.sigma_roll, r.sigma_pitch,
            r.mounting_changed ? 1 : 0};
  });
}

PLANARVO_API void planarvo_stats_table_free(planarvo_stats_table* table) { delete table; }

}  // extern "C"
