/* A C caller of planarvo: tracks a data set with given camera extrinsics and writes the robot's
 * trajectory (TUM), then calibrates the camera's extrinsics from the same drive and prints them
 * with their standard deviations.
 *
 *   track_and_calibrate DATASET EXTRINSICS.yaml TRAJECTORY.txt [CALIBRATED.yaml]
 *
 * DATASET is a data set directory (docs/formats.md; `planarvo simulate --out DIR` makes one).
 * The calibration uses the data set's wheel odometry (odometry.txt) when it has some, else the
 * nonholonomic method with its direction labels (direction.txt) and the camera height from
 * EXTRINSICS.yaml. CALIBRATED.yaml, when given, receives the calibrated extrinsics with their
 * covariance. Exit status: 0 done; 1 a step ran but failed (no OpenCL device, a file that could
 * not be written, a calibration the drive does not determine); 2 bad arguments or input files.
 *
 * Build against an installed planarvo with
 *   cc track_and_calibrate.c -lm $(pkg-config --cflags --libs planarvo)
 */
#include <planarvo/planarvo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef M_PI /* not in strict ISO C */
#define M_PI 3.14159265358979323846
#endif

/* Prints what failed with the library's message and returns the exit status for it. */
static int fail(const char* what, planarvo_status status) {
  fprintf(stderr, "track_and_calibrate: %s: %s\n", what, planarvo_last_error());
  return status == PLANARVO_ERROR_INVALID_INPUT || status == PLANARVO_ERROR_INVALID_ARGUMENT ? 2 : 1;
}

/* Tracks every frame of the data set and writes the poses (relative to the first frame) as a TUM
 * trajectory. Returns an exit status. */
static int track(planarvo_context* context, planarvo_dataset* dataset, const planarvo_dataset_info* info,
                 const planarvo_extrinsics* extrinsics, const char* trajectory_path) {
  const size_t n = (size_t)info->frame_count;
  double* times = malloc(n * sizeof *times);
  planarvo_se2* poses = malloc(n * sizeof *poses);
  planarvo_tracker* tracker = NULL;
  int lost = 0, exit_status = 0;
  if (times == NULL || poses == NULL) {
    fprintf(stderr, "track_and_calibrate: out of memory for %zu frames\n", n);
    exit_status = 1;
  }
  planarvo_status status = PLANARVO_OK;
  if (exit_status == 0) status = planarvo_tracker_create(context, &info->camera, extrinsics, NULL, &tracker);
  if (status != PLANARVO_OK) exit_status = fail("planarvo_tracker_create", status);
  for (size_t i = 0; exit_status == 0 && i < n; ++i) {
    planarvo_frame_data data;
    planarvo_image image;
    planarvo_track_result result;
    result.struct_size = sizeof result;
    if ((status = planarvo_dataset_frame_data(dataset, (int64_t)i, &data)) != PLANARVO_OK ||
        (status = planarvo_dataset_frame(dataset, (int64_t)i, &image)) != PLANARVO_OK ||
        (status = planarvo_tracker_track(tracker, &image, data.timestamp, &result)) != PLANARVO_OK) {
      exit_status = fail("tracking", status);
      break;
    }
    times[i] = data.timestamp;
    poses[i] = result.pose;
    lost += result.status == PLANARVO_TRACK_LOST;
  }
  if (exit_status == 0) {
    status = planarvo_write_tum(trajectory_path, times, poses, n);
    if (status != PLANARVO_OK) exit_status = fail(trajectory_path, status);
  }
  if (exit_status == 0 && n > 0)
    printf("tracked %zu frames (%d lost); last pose x %.4f m, y %.4f m, heading %.3f deg; wrote %s\n", n, lost,
           poses[n - 1].x, poses[n - 1].y, poses[n - 1].theta * 180.0 / M_PI, trajectory_path);
  planarvo_tracker_destroy(tracker);
  free(times);
  free(poses);
  return exit_status;
}

/* Calibrates the extrinsics from the drive, prints them and writes them to out_path (when not
 * NULL). Returns an exit status. */
static int calibrate(planarvo_context* context, planarvo_dataset* dataset, const planarvo_dataset_info* info,
                     double height, const char* out_path) {
  static const char* const names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  planarvo_camera_calibration_options options;
  planarvo_camera_calibration_options_init(&options);
  if (!info->has_odometry) {
    if (!info->has_direction) {
      fprintf(stderr, "track_and_calibrate: the data set has neither odometry.txt nor direction.txt: "
                      "nothing to calibrate against\n");
      return 2;
    }
    options.method = PLANARVO_CALIBRATE_NONHOLONOMIC; /* cannot see the height: give it */
    options.height = height;
  }
  planarvo_camera_calibration_result result;
  result.struct_size = sizeof result;
  const planarvo_status status = planarvo_calibrate_dataset(context, dataset, &options, &result);
  if (status != PLANARVO_OK) return fail("calibration", status);

  const double value[6] = {result.extrinsics.x,    result.extrinsics.y,     result.extrinsics.z,
                           result.extrinsics.roll, result.extrinsics.pitch, result.extrinsics.yaw};
  printf("calibrated extrinsics (%s method), standard deviations:\n",
         options.method == PLANARVO_CALIBRATE_ODOMETRY ? "odometry" : "nonholonomic");
  for (int i = 0; i < 6; ++i) {
    const int angle = i >= 3;
    const double scale = angle ? 180.0 / M_PI : 1000.0; /* degrees, millimetres */
    const double sd = sqrt(result.covariance[i * 7]);
    if (result.estimated[i])
      printf("  %-5s %10.3f %s +- %.3f\n", names[i], value[i] * scale, angle ? "deg" : "mm ", sd * scale);
    else
      printf("  %-5s %10.3f %s (given)\n", names[i], value[i] * scale, angle ? "deg" : "mm ");
  }
  if (out_path == NULL) return 0;
  /* The names of the estimated parameters, as the file records them. */
  char list[64] = "";
  size_t at = 0;
  for (int i = 0; i < 6; ++i)
    if (result.estimated[i])
      at += (size_t)snprintf(list + at, sizeof list - at, "%s%s", at ? "," : "", names[i]);
  const planarvo_status saved = planarvo_extrinsics_save(out_path, &result.extrinsics, result.covariance, list,
                                                         "planarvo_calibrate_dataset", "examples/c");
  if (saved != PLANARVO_OK) return fail(out_path, saved);
  printf("wrote %s\n", out_path);
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 4 || argc > 5) {
    fprintf(stderr, "usage: track_and_calibrate DATASET EXTRINSICS.yaml TRAJECTORY.txt [CALIBRATED.yaml]\n");
    return 2;
  }
  planarvo_extrinsics extrinsics;
  planarvo_status status = planarvo_extrinsics_load(argv[2], &extrinsics);
  if (status != PLANARVO_OK) return fail(argv[2], status);

  planarvo_dataset* dataset = NULL;
  status = planarvo_dataset_open(argv[1], NULL, &dataset);
  if (status != PLANARVO_OK) return fail(argv[1], status);
  planarvo_dataset_info info;
  info.struct_size = sizeof info;
  status = planarvo_dataset_info_get(dataset, &info);
  if (status != PLANARVO_OK) {
    planarvo_dataset_destroy(dataset);
    return fail(argv[1], status);
  }
  printf("%s: %lld frames, %dx%d, %.2f s\n", argv[1], (long long)info.frame_count, info.camera.width,
         info.camera.height, info.last_timestamp - info.first_timestamp);

  /* The default device: PLANARVO_DEVICE, else the first GPU or accelerator, else the first one. */
  planarvo_context* context = NULL;
  status = planarvo_context_create(NULL, &context);
  int exit_status = status == PLANARVO_OK ? 0 : fail("planarvo_context_create", status);
  if (exit_status == 0) exit_status = track(context, dataset, &info, &extrinsics, argv[3]);
  if (exit_status == 0) exit_status = calibrate(context, dataset, &info, extrinsics.z, argc > 4 ? argv[4] : NULL);
  planarvo_context_destroy(context);
  planarvo_dataset_destroy(dataset);
  return exit_status;
}
