// C API: camera and extrinsics YAML, TUM trajectories.
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "capi/convert.h"
#include "capi/status.h"
#include "core/error.h"
#include "io/formats.h"
#include "io/stats.h"

using planarvo::capi::guard;
using planarvo::capi::require;

namespace {
void require_path(const char* path, const char* fn) {
  require(path != nullptr && *path != '\0', (std::string(fn) + ": path is NULL or empty").c_str());
}
}  // namespace

extern "C" {

PLANARVO_API planarvo_status planarvo_camera_load(const char* path, planarvo_camera* camera) {
  return guard([&] {
    require_path(path, "planarvo_camera_load");
    require(camera != nullptr, "planarvo_camera_load: camera is NULL");
    *camera = planarvo::capi::to_c(planarvo::io::read_camera_yaml(path));
  });
}

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

PLANARVO_API planarvo_status planarvo_extrinsics_load(const char* path, planarvo_extrinsics* e) {
  return guard([&] {
    require_path(path, "planarvo_extrinsics_load");
    require(e != nullptr, "planarvo_extrinsics_load: extrinsics is NULL");
    *e = planarvo::capi::to_c(planarvo::io::read_extrinsics_yaml(path).value);
  });
}

PLANARVO_API planarvo_status planarvo_extrinsics_save(const char* path, const planarvo_extrinsics* e,
                                                      const double* covariance, const char* estimated,
                                                      const char* method, const char* notes) {
  return guard([&] {
    require_path(path, "planarvo_extrinsics_save");
    require(e != nullptr, "planarvo_extrinsics_save: extrinsics is NULL");
    planarvo::io::ExtrinsicsFile f;
    f.value = planarvo::capi::to_cpp(*e);
    for (double v : {e->x, e->y, e->z, e->roll, e->pitch, e->yaw})
      require(std::isfinite(v), "planarvo_extrinsics_save: a value is NaN or inf");
    if (covariance) f.covariance = planarvo::capi::matrix_from_c<6>(covariance);
    if (estimated) {
      std::stringstream ss(estimated);
      std::string name;
      while (std::getline(ss, name, ','))
        if (!name.empty()) f.estimated.push_back(name);
    }
    if (method) f.method = method;
    if (notes) f.notes = notes;
    planarvo::io::write_extrinsics_yaml(path, f);
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
    const std::vector<planarvo::io::StampedPose> v = planarvo::io::read_tum(path);
    if (count) *count = v.size();
    if (capacity == 0) return;
    if (capacity < v.size())
      planarvo::throw_invalid_argument("planarvo_read_tum: " + std::string(path) + " has " + std::to_string(v.size()) +
                                       " poses, the arrays hold " + std::to_string(capacity));
    for (size_t i = 0; i < v.size(); ++i) {
      timestamps[i] = v[i].t;
      poses[i] = planarvo::capi::to_c(v[i].pose);
    }
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

}  // extern "C"
