/*
 * planarvo: dense planar visual odometry from a downward-looking camera, with automatic
 * calibration of the camera's pose on the robot (Zienkiewicz & Davison, "Extrinsics
 * Autocalibration for Dense Planar Visual Odometry").
 *
 * This is the library's whole public interface: a C API, callable from C, C++, Python (ctypes)
 * and anything else with a C FFI.
 *
 * Conventions (frames, angles, units): SI units everywhere (metres, radians, seconds). The robot
 * frame is x forward, y left, z up (ROS REP-103) with the ground at z = 0; the camera frame is
 * OpenCV's (x right, y down, z forward). Extrinsics T_robot_camera map camera coordinates into
 * robot coordinates, R = Rz(yaw) Ry(pitch) Rx(roll) R0, with R0 the camera looking straight
 * down, image top towards the robot's front.
 *
 * Rules that hold for every function:
 * - Every function returns a planarvo_status. PLANARVO_OK is 0. A function never lets a C++
 *   exception out and never aborts on bad input.
 * - On failure, planarvo_last_error() returns a message for the calling thread's most recent
 *   failed call (it is thread-local; a successful call does not clear it).
 * - Objects are opaque handles created by planarvo_X_create and released by planarvo_X_destroy,
 *   which accepts NULL. Strings and arrays passed in are copied; the library keeps no pointer to
 *   caller memory after a call returns, unless a function says otherwise.
 * - Option structs begin with struct_size: set it to sizeof(the struct) and initialise the rest
 *   with the matching planarvo_X_options_init(), so that later versions can add fields at the end
 *   without breaking callers built against this header.
 * - Thread safety: functions without a handle are thread-safe. A handle may be used from any
 *   thread, but from one thread at a time; different handles may be used concurrently.
 */
#ifndef PLANARVO_PLANARVO_H
#define PLANARVO_PLANARVO_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#if defined(PLANARVO_BUILDING_LIBRARY)
#define PLANARVO_API __declspec(dllexport)
#else
#define PLANARVO_API __declspec(dllimport)
#endif
#else
#define PLANARVO_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------------ */
/* Version                                                                                     */

#define PLANARVO_VERSION_MAJOR 0
#define PLANARVO_VERSION_MINOR 1
#define PLANARVO_VERSION_PATCH 0
#define PLANARVO_VERSION_NUMBER \
  (PLANARVO_VERSION_MAJOR * 10000 + PLANARVO_VERSION_MINOR * 100 + PLANARVO_VERSION_PATCH)

/* The run-time library's PLANARVO_VERSION_NUMBER and its "major.minor.patch" string. */
PLANARVO_API int planarvo_version_number(void);
PLANARVO_API const char* planarvo_version_string(void);

/* ------------------------------------------------------------------------------------------ */
/* Status and errors                                                                           */

typedef enum planarvo_status {
  PLANARVO_OK = 0,
  PLANARVO_ERROR_INVALID_ARGUMENT = 1, /* a NULL pointer, a bad size or value in a call */
  PLANARVO_ERROR_INVALID_INPUT = 2,    /* a file or data set is missing, unreadable, malformed */
  PLANARVO_ERROR_IO = 3,               /* a file could not be written */
  PLANARVO_ERROR_NO_DEVICE = 4,        /* no usable OpenCL device */
  PLANARVO_ERROR_OPENCL = 5,           /* an OpenCL call or kernel build failed */
  PLANARVO_ERROR_FAILED = 6,           /* ran, but failed: lost tracking, no convergence... */
  PLANARVO_ERROR_CANCELLED = 7,        /* a progress callback returned non-zero */
  PLANARVO_ERROR_BUFFER_TOO_SMALL = 8, /* an output buffer is too small; see the function */
  PLANARVO_ERROR_INTERNAL = 9          /* a bug in planarvo: please report it */
} planarvo_status;

/* The message of the calling thread's last failed call ("" if none). Valid until the thread's
 * next failing call. */
PLANARVO_API const char* planarvo_last_error(void);
/* A fixed name for a status code, e.g. "PLANARVO_ERROR_INVALID_INPUT". */
PLANARVO_API const char* planarvo_status_name(planarvo_status status);

/* Long-running calls report progress through this callback: fraction in [0, 1], a short label
 * of the current stage. Return non-zero to cancel: the call then fails with
 * PLANARVO_ERROR_CANCELLED. */
typedef int (*planarvo_progress_fn)(void* user_data, double fraction, const char* stage);

/* ------------------------------------------------------------------------------------------ */
/* Plain data                                                                                  */

/* Pinhole camera with OpenCV's radial-tangential distortion (k1 k2 p1 p2 k3), pixel (0,0) the
 * centre of the top-left pixel. */
typedef struct planarvo_camera {
  int32_t width, height;
  double fx, fy, cx, cy;
  double k1, k2, p1, p2, k3;
} planarvo_camera;

/* Camera pose on the robot: centre (x, y, z) in metres, z the height above the ground;
 * roll, pitch, yaw in radians (see the header comment). */
typedef struct planarvo_extrinsics {
  double x, y, z;
  double roll, pitch, yaw;
} planarvo_extrinsics;

/* A planar pose or motion (metres, radians). */
typedef struct planarvo_se2 {
  double x, y, theta;
} planarvo_se2;

typedef enum planarvo_pixel_format {
  PLANARVO_GRAY8 = 0,  /* 1 byte per pixel */
  PLANARVO_BGR8 = 1,   /* 3 bytes per pixel, OpenCV's order */
  PLANARVO_RGB8 = 2,   /* 3 bytes per pixel */
  PLANARVO_GRAY32F = 3 /* 4-byte float per pixel, grey levels 0..255 */
} planarvo_pixel_format;

/* An image in caller memory: stride is the number of bytes between the starts of two rows. */
typedef struct planarvo_image {
  const void* data;
  int32_t width, height;
  size_t stride;
  planarvo_pixel_format format;
} planarvo_image;

/* Reads an OpenCV calibration YAML (image_width, image_height, camera_matrix,
 * distortion_coefficients). */
PLANARVO_API planarvo_status planarvo_camera_load(const char* path, planarvo_camera* camera);
PLANARVO_API planarvo_status planarvo_camera_save(const char* path, const planarvo_camera* camera);

/* Reads extrinsics YAML (x y z roll pitch yaw required; a T_robot_camera that disagrees with them
 * is an error). covariance (6x6 row-major, order x y z roll pitch yaw) may be NULL. */
PLANARVO_API planarvo_status planarvo_extrinsics_load(const char* path, planarvo_extrinsics* e);
/* Writes extrinsics YAML (formats.md). covariance: 36 doubles or NULL (zeros); estimated:
 * comma-separated names such as "x,yaw" or NULL; method and notes may be NULL. */
PLANARVO_API planarvo_status planarvo_extrinsics_save(const char* path,
                                                      const planarvo_extrinsics* e,
                                                      const double* covariance,
                                                      const char* estimated, const char* method,
                                                      const char* notes);
/* T_robot_camera as a 4x4 row-major matrix. */
PLANARVO_API planarvo_status planarvo_extrinsics_matrix(const planarvo_extrinsics* e,
                                                        double matrix[16]);

/* ------------------------------------------------------------------------------------------ */
/* OpenCL devices and the context                                                              */

typedef struct planarvo_device_info {
  size_t struct_size;
  int32_t index;             /* global index: what --device N and PLANARVO_DEVICE=N select */
  char platform_name[128];
  char device_name[128];
  char device_type[16];      /* "GPU", "CPU", "ACCELERATOR", "OTHER" */
  char device_version[128];  /* e.g. "OpenCL 3.0 PoCL ..." */
  char opencl_c_version[64]; /* e.g. "OpenCL C 1.2 PoCL" */
  char driver_version[64];
  int32_t image_support;
  int32_t fp64;
  uint64_t local_mem_size;
  uint64_t global_mem_size;
  uint64_t max_work_group_size;
  uint32_t compute_units;
} planarvo_device_info;

/* Lists every OpenCL device. Call with devices = NULL to get the count; then with an array of
 * capacity entries, each with struct_size set. Fails with PLANARVO_ERROR_BUFFER_TOO_SMALL (and
 * sets *count) when capacity is less than the count. A machine without OpenCL has count 0. */
PLANARVO_API planarvo_status planarvo_list_devices(planarvo_device_info* devices, size_t capacity,
                                                   size_t* count);

typedef struct planarvo_context_options {
  size_t struct_size;
  /* "" or NULL: the environment variable PLANARVO_DEVICE, else the first GPU or accelerator,
   * else the first device. A number selects by index (planarvo_list_devices), anything else is a
   * case-insensitive substring of "platform name / device name". */
  const char* device;
  /* Directory of the on-disk kernel program cache. NULL: $PLANARVO_CACHE_DIR, else
   * $XDG_CACHE_HOME/planarvo, else ~/.cache/planarvo. */
  const char* cache_dir;
  int32_t disable_cache; /* non-zero: always compile from source */
  /* Directory of prebuilt program binaries (planarvo_context_export_kernels). When set, the
   * engine loads those and never compiles: what FPGA runtimes need. */
  const char* kernel_binaries_dir;
} planarvo_context_options;

/* Owns an OpenCL device, its queue and its programs. Thread safety: one thread at a time. */
typedef struct planarvo_context planarvo_context;

PLANARVO_API void planarvo_context_options_init(planarvo_context_options* options);
/* options may be NULL for the defaults. Fails with PLANARVO_ERROR_NO_DEVICE when no device
 * matches. */
PLANARVO_API planarvo_status planarvo_context_create(const planarvo_context_options* options,
                                                     planarvo_context** context);
PLANARVO_API void planarvo_context_destroy(planarvo_context* context);
PLANARVO_API planarvo_status planarvo_context_device(const planarvo_context* context,
                                                     planarvo_device_info* info);
/* Builds every kernel program for the context's device and writes the binaries into dir (created
 * if missing), for later use with kernel_binaries_dir. */
PLANARVO_API planarvo_status planarvo_context_export_kernels(planarvo_context* context,
                                                             const char* dir);
/* Builds (or loads) every kernel program now, so that the first frame does not pay for it. */
PLANARVO_API planarvo_status planarvo_context_prepare_kernels(planarvo_context* context);

/* ------------------------------------------------------------------------------------------ */
/* Data sets (shared/spec/formats.md)                                                          */

/* A data set directory (camera.yaml, frames.txt + images/, or a video; optional odometry.txt,
 * direction.txt, groundtruth.txt, extrinsics.yaml, extrinsics_gt.yaml), read and validated on
 * open. Image files are decoded on demand by planarvo_dataset_frame. Thread safety: one thread at
 * a time. */
typedef struct planarvo_dataset planarvo_dataset;

typedef struct planarvo_dataset_options {
  size_t struct_size;
  /* A video file standing in for images/ + frames.txt; NULL to use frames.txt. */
  const char* video;
  /* Non-zero: decode every image while opening, so that an unreadable image or one of the wrong
   * size is reported now rather than when its frame is read. */
  int32_t verify_images;
  planarvo_progress_fn progress;
  void* progress_user_data;
} planarvo_dataset_options;

/* What a data set holds. */
typedef struct planarvo_dataset_info {
  size_t struct_size;
  int64_t frame_count;
  double first_timestamp, last_timestamp;
  planarvo_camera camera;
  int32_t has_odometry, has_direction, has_groundtruth;
  int32_t has_extrinsics, has_extrinsics_gt;
  planarvo_extrinsics extrinsics;    /* valid when has_extrinsics */
  planarvo_extrinsics extrinsics_gt; /* valid when has_extrinsics_gt */
} planarvo_dataset_info;

typedef struct planarvo_frame_data {
  double timestamp;
  /* Robot pose in the odometry frame, interpolated to the frame's time; valid when has_odometry
   * (a frame outside the odometry's time span has none). */
  int32_t has_odometry;
  planarvo_se2 odometry;
  /* True robot pose (groundtruth.txt); valid when has_groundtruth. */
  int32_t has_groundtruth;
  planarvo_se2 groundtruth;
  /* Direction of the interval from the previous frame to this one: +1 forwards, -1 backwards,
   * 0 no linear motion; valid when has_direction (never for frame 0). */
  int32_t has_direction;
  int32_t direction;
} planarvo_frame_data;

PLANARVO_API void planarvo_dataset_options_init(planarvo_dataset_options* options);
PLANARVO_API planarvo_status planarvo_dataset_open(const char* directory,
                                                   const planarvo_dataset_options* options,
                                                   planarvo_dataset** dataset);
PLANARVO_API void planarvo_dataset_destroy(planarvo_dataset* dataset);
PLANARVO_API planarvo_status planarvo_dataset_info_get(const planarvo_dataset* dataset,
                                                       planarvo_dataset_info* info);
PLANARVO_API planarvo_status planarvo_dataset_frame_data(const planarvo_dataset* dataset,
                                                         int64_t index, planarvo_frame_data* data);
/* Decodes frame index as 8-bit grey. *image points into memory owned by the data set, valid until
 * the next call on it or its destruction. */
PLANARVO_API planarvo_status planarvo_dataset_frame(planarvo_dataset* dataset, int64_t index,
                                                    planarvo_image* image);

/* Writes a TUM trajectory (t x y z qx qy qz qw, z = 0, rotation about z). */
PLANARVO_API planarvo_status planarvo_write_tum(const char* path, const double* timestamps,
                                                const planarvo_se2* poses, size_t count);

/* ------------------------------------------------------------------------------------------ */
/* Simulator                                                                                   */

typedef enum planarvo_motion_profile {
  PLANARVO_MOTION_MIXED = 0,    /* forward and backward driving, turns both ways, turning in
                                   place, stops: everything calibration needs */
  PLANARVO_MOTION_STRAIGHT = 1, /* forwards and backwards along one line */
  PLANARVO_MOTION_CIRCLE = 2,   /* one constant-curvature circle */
  PLANARVO_MOTION_SPIN = 3      /* turning in place */
} planarvo_motion_profile;

typedef struct planarvo_sim_options {
  size_t struct_size;
  const char* texture;        /* a photograph of the ground (any cv::imread format); required */
  double texel_size;          /* metres per texture pixel; default 0.0004 */
  planarvo_extrinsics extrinsics; /* default: x 0.24, y -0.02, z 0.18, roll 12.4 deg, pitch
                                     17.6 deg, yaw -9.2 deg (the paper's configuration 1) */
  planarvo_camera camera;     /* default: 640x480, 80 deg horizontal field of view, mild barrel
                                 distortion */
  double seconds;             /* default 10 */
  double fps;                 /* default 30 */
  uint64_t seed;              /* default 1 */
  planarvo_motion_profile motion; /* default PLANARVO_MOTION_MIXED */
  double max_speed;           /* peak linear speed, m/s; default 0.8 */
  double max_turn_rate;       /* peak angular speed, rad/s; default 1.5 */
  double pixel_noise;         /* standard deviation of additive pixel noise, grey levels; def. 1 */
  double gain_variation;      /* amplitude of the slow camera gain change, relative; def. 0.05 */
  double odometry_noise;      /* wheel odometry error, relative standard deviation per wheel
                                 travel; default 0.01 */
  int32_t supersampling;      /* samples per pixel along each axis; default 3 */
  planarvo_progress_fn progress;
  void* progress_user_data;
} planarvo_sim_options;

PLANARVO_API void planarvo_sim_options_init(planarvo_sim_options* options);
/* The simulator's camera for a size and a horizontal field of view (degrees, measured through
 * the lens distortion between the outermost pixel columns), with its default mild barrel
 * distortion. */
PLANARVO_API planarvo_status planarvo_sim_default_camera(int32_t width, int32_t height, double fov_deg,
                                                         planarvo_camera* camera);
/* Renders a data set in the layout of planarvo_dataset_open into out_directory (created if
 * missing): camera.yaml, images/, frames.txt, odometry.txt, direction.txt, groundtruth.txt,
 * extrinsics_gt.yaml. Deterministic for a seed on a given device. */
PLANARVO_API planarvo_status planarvo_simulate(planarvo_context* context,
                                               const planarvo_sim_options* options,
                                               const char* out_directory);

#ifdef __cplusplus
}
#endif

#endif /* PLANARVO_PLANARVO_H */
