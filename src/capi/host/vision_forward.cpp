// The C API functions that live in the vision module, forwarded to it: each looks its
// function up on the first call (loading the module then) and calls it. One per function of
// planarvo.h that needs images or an OpenCL device; the test capi_exports_test checks that the
// C API library exports every function of the header.
#include "capi/host/vision_module.h"
#include "planarvo/planarvo.h"

namespace {

template <class F>
F lookup(const char* name) {
  return reinterpret_cast<F>(planarvo::capi::host::vision_symbol(name));
}

}  // namespace

// Each forwarder keeps its function pointer in a static: the module, once loaded, stays.
#define PLANARVO_FORWARD(name) \
  static const auto fn = lookup<decltype(&name)>(#name)

extern "C" {

PLANARVO_API planarvo_status planarvo_camera_load(const char* path, planarvo_camera* camera) {
  PLANARVO_FORWARD(planarvo_camera_load);
  return fn ? fn(path, camera) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_camera_save(const char* path, const planarvo_camera* camera) {
  PLANARVO_FORWARD(planarvo_camera_save);
  return fn ? fn(path, camera) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_extrinsics_load(const char* path, planarvo_extrinsics* e) {
  PLANARVO_FORWARD(planarvo_extrinsics_load);
  return fn ? fn(path, e) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_extrinsics_save(const char* path, const planarvo_extrinsics* e, const double* covariance, const char* estimated, const char* method, const char* notes) {
  PLANARVO_FORWARD(planarvo_extrinsics_save);
  return fn ? fn(path, e, covariance, estimated, method, notes) : PLANARVO_ERROR_INTERNAL;
}
PLANARVO_API planarvo_status planarvo_camera_calibration_save(const char* path, const planarvo_camera_calibration_result* result, const char* notes) {
  PLANARVO_FORWARD(planarvo_camera_calibration_save);
  return fn ? fn(path, result, notes) : PLANARVO_ERROR_INTERNAL;
}
PLANARVO_API planarvo_status planarvo_calibration_save(const char* path, const planarvo_calibration_result* result, planarvo_calibration_method method, int32_t metric_sensor, const char* notes) {
  PLANARVO_FORWARD(planarvo_calibration_save);
  return fn ? fn(path, result, method, metric_sensor, notes) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_extrinsics_matrix(const planarvo_extrinsics* e, double matrix[16]) {
  PLANARVO_FORWARD(planarvo_extrinsics_matrix);
  return fn ? fn(e, matrix) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_list_devices(planarvo_device_info* devices, size_t capacity, size_t* count) {
  PLANARVO_FORWARD(planarvo_list_devices);
  return fn ? fn(devices, capacity, count) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_context_options_init(planarvo_context_options* options) {
  PLANARVO_FORWARD(planarvo_context_options_init);
  if (fn) fn(options);
}

PLANARVO_API planarvo_status planarvo_context_create(const planarvo_context_options* options, planarvo_context** context) {
  PLANARVO_FORWARD(planarvo_context_create);
  return fn ? fn(options, context) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_context_destroy(planarvo_context* context) {
  PLANARVO_FORWARD(planarvo_context_destroy);
  if (fn) fn(context);
}

PLANARVO_API planarvo_status planarvo_context_device(const planarvo_context* context, planarvo_device_info* info) {
  PLANARVO_FORWARD(planarvo_context_device);
  return fn ? fn(context, info) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API const char* planarvo_context_cache_dir(const planarvo_context* context) {
  PLANARVO_FORWARD(planarvo_context_cache_dir);
  return fn ? fn(context) : nullptr;
}

PLANARVO_API planarvo_status planarvo_context_export_kernels(planarvo_context* context, const char* dir) {
  PLANARVO_FORWARD(planarvo_context_export_kernels);
  return fn ? fn(context, dir) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_context_export_kernels_for(planarvo_context* context, const char* dir, const char* uses, size_t* exported) {
  PLANARVO_FORWARD(planarvo_context_export_kernels_for);
  return fn ? fn(context, dir, uses, exported) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_context_prepare_kernels(planarvo_context* context) {
  PLANARVO_FORWARD(planarvo_context_prepare_kernels);
  return fn ? fn(context) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_dataset_options_init(planarvo_dataset_options* options) {
  PLANARVO_FORWARD(planarvo_dataset_options_init);
  if (fn) fn(options);
}

PLANARVO_API planarvo_status planarvo_dataset_open(const char* directory, const planarvo_dataset_options* options, planarvo_dataset** dataset) {
  PLANARVO_FORWARD(planarvo_dataset_open);
  return fn ? fn(directory, options, dataset) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_bag_topics(const char* path, char* buffer, size_t size, size_t* needed) {
  PLANARVO_FORWARD(planarvo_bag_topics);
  return fn ? fn(path, buffer, size, needed) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_dataset_destroy(planarvo_dataset* dataset) {
  PLANARVO_FORWARD(planarvo_dataset_destroy);
  if (fn) fn(dataset);
}

PLANARVO_API planarvo_status planarvo_dataset_info_get(const planarvo_dataset* dataset, planarvo_dataset_info* info) {
  PLANARVO_FORWARD(planarvo_dataset_info_get);
  return fn ? fn(dataset, info) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_dataset_set_roi(planarvo_dataset* dataset, const planarvo_region* roi) {
  PLANARVO_FORWARD(planarvo_dataset_set_roi);
  return fn ? fn(dataset, roi) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_dataset_set_readout(planarvo_dataset* dataset, double seconds,
                                                          const char* source) {
  PLANARVO_FORWARD(planarvo_dataset_set_readout);
  return fn ? fn(dataset, seconds, source) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_dataset_frame_data(const planarvo_dataset* dataset, int64_t index, planarvo_frame_data* data) {
  PLANARVO_FORWARD(planarvo_dataset_frame_data);
  return fn ? fn(dataset, index, data) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_dataset_frame(planarvo_dataset* dataset, int64_t index, planarvo_image* image) {
  PLANARVO_FORWARD(planarvo_dataset_frame);
  return fn ? fn(dataset, index, image) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_write_tum(const char* path, const double* timestamps, const planarvo_se2* poses, size_t count) {
  PLANARVO_FORWARD(planarvo_write_tum);
  return fn ? fn(path, timestamps, poses, count) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_write_plane(const char* path, const planarvo_plane_attitude* rows, size_t count) {
  PLANARVO_FORWARD(planarvo_write_plane);
  return fn ? fn(path, rows, count) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_stats_writer_open(const char* path, planarvo_stats_writer** writer) {
  PLANARVO_FORWARD(planarvo_stats_writer_open);
  return fn ? fn(path, writer) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_stats_writer_add(planarvo_stats_writer* writer, const planarvo_frame_stats* row) {
  PLANARVO_FORWARD(planarvo_stats_writer_add);
  return fn ? fn(writer, row) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_stats_writer_close(planarvo_stats_writer* writer) {
  PLANARVO_FORWARD(planarvo_stats_writer_close);
  return fn ? fn(writer) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_stats_writer_discard(planarvo_stats_writer* writer) {
  PLANARVO_FORWARD(planarvo_stats_writer_discard);
  if (fn) fn(writer);
}

PLANARVO_API void planarvo_sim_options_init(planarvo_sim_options* options) {
  PLANARVO_FORWARD(planarvo_sim_options_init);
  if (fn) fn(options);
}

PLANARVO_API planarvo_status planarvo_sim_default_camera(int32_t width, int32_t height, double fov_deg, planarvo_camera* camera) {
  PLANARVO_FORWARD(planarvo_sim_default_camera);
  return fn ? fn(width, height, fov_deg, camera) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_simulate(planarvo_context* context, const planarvo_sim_options* options, const char* out_directory) {
  PLANARVO_FORWARD(planarvo_simulate);
  return fn ? fn(context, options, out_directory) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_tracker_options_init(planarvo_tracker_options* options) {
  PLANARVO_FORWARD(planarvo_tracker_options_init);
  if (fn) fn(options);
}

PLANARVO_API planarvo_status planarvo_tracker_create(planarvo_context* context, const planarvo_camera* camera, const planarvo_extrinsics* extrinsics, const planarvo_tracker_options* options, planarvo_tracker** tracker) {
  PLANARVO_FORWARD(planarvo_tracker_create);
  return fn ? fn(context, camera, extrinsics, options, tracker) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_tracker_destroy(planarvo_tracker* tracker) {
  PLANARVO_FORWARD(planarvo_tracker_destroy);
  if (fn) fn(tracker);
}

PLANARVO_API planarvo_status planarvo_tracker_track(planarvo_tracker* tracker, const planarvo_image* image, double timestamp, planarvo_track_result* result) {
  PLANARVO_FORWARD(planarvo_tracker_track);
  return fn ? fn(tracker, image, timestamp, result) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_tracker_odometry(planarvo_tracker* tracker, const planarvo_se2* pose) {
  PLANARVO_FORWARD(planarvo_tracker_odometry);
  return fn ? fn(tracker, pose) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_tracker_reset(planarvo_tracker* tracker) {
  PLANARVO_FORWARD(planarvo_tracker_reset);
  return fn ? fn(tracker) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_tracker_save_flat_field(planarvo_tracker* tracker, const char* path) {
  PLANARVO_FORWARD(planarvo_tracker_save_flat_field);
  return fn ? fn(tracker, path) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_tracker_residuals(planarvo_tracker* tracker, int32_t level, float* residual, float* weight, float* intensity, size_t capacity, int32_t* width, int32_t* height, double* threshold) {
  PLANARVO_FORWARD(planarvo_tracker_residuals);
  return fn ? fn(tracker, level, residual, weight, intensity, capacity, width, height, threshold) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_fit_body_lean(const double* timestamps, const planarvo_se2* motions, const double* roll, const double* pitch, const int32_t* use, size_t count, planarvo_body_lean* lean) {
  PLANARVO_FORWARD(planarvo_fit_body_lean);
  return fn ? fn(timestamps, motions, roll, pitch, use, count, lean) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_evaluate_motions(const planarvo_se2* estimated, const planarvo_se2* truth, const double* dt, const int32_t* valid, size_t count, double gross_threshold, planarvo_motion_accuracy* accuracy) {
  PLANARVO_FORWARD(planarvo_evaluate_motions);
  return fn ? fn(estimated, truth, dt, valid, count, gross_threshold, accuracy) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_roll_pitch_options_init(planarvo_roll_pitch_options* options) {
  PLANARVO_FORWARD(planarvo_roll_pitch_options_init);
  if (fn) fn(options);
}

PLANARVO_API planarvo_status planarvo_roll_pitch_create(planarvo_context* context, const planarvo_camera* camera, const planarvo_roll_pitch_options* options, planarvo_roll_pitch** estimator) {
  PLANARVO_FORWARD(planarvo_roll_pitch_create);
  return fn ? fn(context, camera, options, estimator) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_roll_pitch_destroy(planarvo_roll_pitch* estimator) {
  PLANARVO_FORWARD(planarvo_roll_pitch_destroy);
  if (fn) fn(estimator);
}

PLANARVO_API planarvo_status planarvo_roll_pitch_add_frame(planarvo_roll_pitch* estimator, const planarvo_image* image, double timestamp, int32_t* complete) {
  PLANARVO_FORWARD(planarvo_roll_pitch_add_frame);
  return fn ? fn(estimator, image, timestamp, complete) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_roll_pitch_estimate(planarvo_roll_pitch* estimator, planarvo_roll_pitch_result* result) {
  PLANARVO_FORWARD(planarvo_roll_pitch_estimate);
  return fn ? fn(estimator, result) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_camera_calibration_options_init(planarvo_camera_calibration_options* options) {
  PLANARVO_FORWARD(planarvo_camera_calibration_options_init);
  if (fn) fn(options);
}

PLANARVO_API planarvo_status planarvo_calibrate_dataset(planarvo_context* context, planarvo_dataset* dataset, const planarvo_camera_calibration_options* options, planarvo_camera_calibration_result* result) {
  PLANARVO_FORWARD(planarvo_calibrate_dataset);
  return fn ? fn(context, dataset, options, result) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_camera_calibrator_create(planarvo_context* context, const planarvo_camera* camera, const planarvo_camera_calibration_options* options, planarvo_camera_calibrator** calibrator) {
  PLANARVO_FORWARD(planarvo_camera_calibrator_create);
  return fn ? fn(context, camera, options, calibrator) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_camera_calibrator_destroy(planarvo_camera_calibrator* calibrator) {
  PLANARVO_FORWARD(planarvo_camera_calibrator_destroy);
  if (fn) fn(calibrator);
}

PLANARVO_API planarvo_status planarvo_camera_calibrator_add_frame(planarvo_camera_calibrator* calibrator, const planarvo_image* image, double timestamp, const planarvo_se2* odometry_pose, const int32_t* direction) {
  PLANARVO_FORWARD(planarvo_camera_calibrator_add_frame);
  return fn ? fn(calibrator, image, timestamp, odometry_pose, direction) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_camera_calibrator_add_odometry(planarvo_camera_calibrator* calibrator, double timestamp, const planarvo_se2* pose) {
  PLANARVO_FORWARD(planarvo_camera_calibrator_add_odometry);
  return fn ? fn(calibrator, timestamp, pose) : PLANARVO_ERROR_INTERNAL;
}
PLANARVO_API planarvo_status planarvo_camera_calibrator_finish(planarvo_camera_calibrator* calibrator, planarvo_camera_calibration_result* result) {
  PLANARVO_FORWARD(planarvo_camera_calibrator_finish);
  return fn ? fn(calibrator, result) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_track_motions(planarvo_context* context, planarvo_dataset* dataset, const planarvo_extrinsics* extrinsics, const planarvo_tracker_options* options, planarvo_motion_pair* pairs, size_t capacity, size_t* count) {
  PLANARVO_FORWARD(planarvo_track_motions);
  return fn ? fn(context, dataset, extrinsics, options, pairs, capacity, count) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_compose_extrinsics(double roll, double pitch, const double* roll_pitch_covariance, const planarvo_calibration_result* graph, planarvo_extrinsics* extrinsics, double* covariance, int32_t* estimated) {
  PLANARVO_FORWARD(planarvo_compose_extrinsics);
  return fn ? fn(roll, pitch, roll_pitch_covariance, graph, extrinsics, covariance, estimated) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_read_tum(const char* path, double* timestamps, planarvo_se2* poses, size_t capacity, size_t* count) {
  PLANARVO_FORWARD(planarvo_read_tum);
  return fn ? fn(path, timestamps, poses, capacity, count) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_mosaic_options_init(planarvo_mosaic_options* options) {
  PLANARVO_FORWARD(planarvo_mosaic_options_init);
  if (fn) fn(options);
}

PLANARVO_API planarvo_status planarvo_mosaic_build(planarvo_context* context, planarvo_dataset* dataset, const planarvo_extrinsics* extrinsics, const double* timestamps, const planarvo_se2* poses, size_t count, const planarvo_mosaic_options* options, planarvo_mosaic** mosaic) {
  PLANARVO_FORWARD(planarvo_mosaic_build);
  return fn ? fn(context, dataset, extrinsics, timestamps, poses, count, options, mosaic) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API void planarvo_mosaic_destroy(planarvo_mosaic* mosaic) {
  if (!mosaic) return;
  PLANARVO_FORWARD(planarvo_mosaic_destroy);
  if (fn) fn(mosaic);
}

PLANARVO_API planarvo_status planarvo_mosaic_info_get(const planarvo_mosaic* mosaic, planarvo_mosaic_info* info) {
  PLANARVO_FORWARD(planarvo_mosaic_info_get);
  return fn ? fn(mosaic, info) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_mosaic_image(const planarvo_mosaic* mosaic, planarvo_image* image) {
  PLANARVO_FORWARD(planarvo_mosaic_image);
  return fn ? fn(mosaic, image) : PLANARVO_ERROR_INTERNAL;
}

PLANARVO_API planarvo_status planarvo_mosaic_save(const planarvo_mosaic* mosaic, const char* image_path) {
  PLANARVO_FORWARD(planarvo_mosaic_save);
  return fn ? fn(mosaic, image_path) : PLANARVO_ERROR_INTERNAL;
}

}  // extern "C"
