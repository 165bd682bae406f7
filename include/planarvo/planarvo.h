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
 * down, image top towards the robot's front. docs/conventions.md gives them in full (motions
 * T_{k-1}^-1 T_k, their covariances, time stamps, direction labels); docs/formats.md describes
 * every file the functions below read and write.
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
#define PLANARVO_VERSION_MINOR 2
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
  PLANARVO_ERROR_INTERNAL = 9,         /* a bug in planarvo: please report it */
  PLANARVO_ERROR_OUT_OF_MEMORY = 10     /* host memory, or the device's for its buffers, ran out */
} planarvo_status;

/* The message of the calling thread's last failed call ("" if none). Valid until the thread's
 * next failing call. Printable: control bytes from the input (NUL, escapes) are written \xNN,
 * and a message over 4096 bytes keeps its start and its end. */
PLANARVO_API const char* planarvo_last_error(void);
/* The C API's functions, one per line "name|return type|parameter types, comma-separated", in the
 * headers' order, generated from them at build time: what language bindings declare their
 * foreign functions from (the Python package's ctypes prototypes come from it). */
PLANARVO_API const char* planarvo_api_signatures(void);
/* A fixed name for a status code, e.g. "PLANARVO_ERROR_INVALID_INPUT". */
PLANARVO_API const char* planarvo_status_name(planarvo_status status);

/* Long-running calls report progress through this callback: fraction in [0, 1], a short label
 * of the current stage. Return non-zero to cancel: the call then fails with
 * PLANARVO_ERROR_CANCELLED. */
typedef int (*planarvo_progress_fn)(void* user_data, double fraction, const char* stage);

/* ------------------------------------------------------------------------------------------ */
/* Plain data                                                                                  */

/* A rectangle of image pixels: columns x .. x + width - 1, rows y .. y + height - 1. */
typedef struct planarvo_region {
  int32_t x, y, width, height;
} planarvo_region;

/* Pinhole camera with OpenCV's radial-tangential distortion (k1 k2 p1 p2 k3), pixel (0,0) the
 * centre of the top-left pixel. Zero-initialise it before filling it in (roi,
 * rolling_shutter_readout and exposure_time were added in 0.2). */
typedef struct planarvo_camera {
  int32_t width, height;
  double fx, fy, cx, cy;
  double k1, k2, p1, p2, k3;
  /* The region of interest: the only pixels of the image the engine uses, for a camera that
   * also sees the horizon, the vehicle's bumper or the sidewalk (camera.yaml's
   * region_of_interest). All zero: the whole image. Otherwise it must lie inside the image and be
   * at least 16 pixels on a side (else PLANARVO_ERROR_INVALID_INPUT). */
  planarvo_region roi;
  /* Rolling shutter (camera.yaml's rolling_shutter_readout, added in 0.2): seconds from reading
   * the first image row to reading the last; 0 = global shutter. A frame's time stamp is when
   * its first row is read; row r of H rows is read at stamp + r / (H - 1) * readout. Negative or
   * not finite: PLANARVO_ERROR_INVALID_INPUT. */
  double rolling_shutter_readout;
  /* Exposure (camera.yaml's exposure_time): seconds each row integrates before it is read; the
   * engine takes each row's image as the sharp one of half the exposure before its read. 0 = not
   * modelled. Negative or not finite: PLANARVO_ERROR_INVALID_INPUT. */
  double exposure_time;
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

/* An image in caller memory: stride is the number of bytes between the starts of two rows, at
 * least width x bytes per pixel, and a multiple of 4 for PLANARVO_GRAY32F (else
 * PLANARVO_ERROR_INVALID_ARGUMENT). */
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
 * is an error). The covariance and notes that planarvo_extrinsics_save writes are not read. */
PLANARVO_API planarvo_status planarvo_extrinsics_load(const char* path, planarvo_extrinsics* e);
/* Writes extrinsics YAML (docs/formats.md). covariance: 36 doubles or NULL (zeros); estimated:
 * comma-separated names such as "x,yaw" or NULL; method and notes may be NULL. */
PLANARVO_API planarvo_status planarvo_extrinsics_save(const char* path,
                                                      const planarvo_extrinsics* e,
                                                      const double* covariance,
                                                      const char* estimated, const char* method,
                                                      const char* notes);
/* Everything an extrinsics YAML holds (docs/formats.md), as planarvo_extrinsics_file_load reads it. */
#define PLANARVO_EXTRINSICS_TEXT_MAX 4096
typedef struct planarvo_extrinsics_file {
  planarvo_extrinsics value;
  double covariance[36];  /* row-major, in x y z roll pitch yaw order; zeros when the file has none */
  int32_t estimated[6];   /* 1 for each parameter the file lists under estimated */
  char method[PLANARVO_EXTRINSICS_TEXT_MAX + 1]; /* "" when the file has none */
  char notes[PLANARVO_EXTRINSICS_TEXT_MAX + 1];
} planarvo_extrinsics_file;
/* Reads the whole extrinsics YAML: the values as planarvo_extrinsics_load does, and the
 * covariance, the estimated parameters, method and notes. PLANARVO_ERROR_INVALID_INPUT naming the
 * file for a malformed file, and for a method or notes longer than PLANARVO_EXTRINSICS_TEXT_MAX
 * bytes (planarvo's writers write none longer). */
PLANARVO_API planarvo_status planarvo_extrinsics_file_load(const char* path, planarvo_extrinsics_file* file);
/* T_robot_camera as a 4x4 row-major matrix. */
PLANARVO_API planarvo_status planarvo_extrinsics_matrix(const planarvo_extrinsics* e,
                                                        double matrix[16]);
/* The name of extrinsics parameter `index` in the order of every covariance and flag array
 * (0 "x", 1 "y", 2 "z", 3 "roll", 4 "pitch", 5 "yaw"), as extrinsics.yaml writes it; NULL for
 * another index. */
PLANARVO_API const char* planarvo_extrinsics_name(int32_t index);

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
  /* 1 when the driver keeps the kernels it compiles in a persistent cache of its own (PoCL's
   * kcache, unless POCL_KERNEL_CACHE=0): planarvo's program cache is then off unless a directory
   * is chosen (planarvo_context_options.cache_dir). Read only when struct_size covers it. */
  int32_t driver_caches_kernels;
} planarvo_device_info;

/* Lists every OpenCL device. Call with devices = NULL to get the count; then with an array of
 * capacity entries, each with struct_size set. Fails with PLANARVO_ERROR_BUFFER_TOO_SMALL (and
 * sets *count) when capacity is less than the count. A machine without OpenCL has count 0.
 * Environment: the first call of this or planarvo_context_create in a process sets
 * POCL_CACHE_DIR to $TMPDIR/planarvo-<uid>/pocl when it is not set and PoCL could not create
 * its own cache directory ($XDG_CACHE_HOME/pocl, else $HOME/.cache/pocl; HOME unset or not
 * writable), since PoCL then finds no device. Setting it changes the process environment
 * (setenv): make that first call before other threads read the environment, or set
 * POCL_CACHE_DIR yourself. */
PLANARVO_API planarvo_status planarvo_list_devices(planarvo_device_info* devices, size_t capacity,
                                                   size_t* count);

typedef struct planarvo_context_options {
  size_t struct_size;
  /* "" or NULL: the environment variable PLANARVO_DEVICE, else the first GPU or accelerator,
   * else the first device. A number selects by index (planarvo_list_devices), anything else is a
   * case-insensitive substring of "platform name / device name". */
  const char* device;
  /* Directory of the on-disk kernel program cache. NULL: $PLANARVO_CACHE_DIR, else none when
   * the driver caches compiled kernels itself (planarvo_device_info.driver_caches_kernels: PoCL,
   * whose own cache serves later runs, and for which writing ours would cost a first run a
   * second compile of every program), else $XDG_CACHE_HOME/planarvo, else ~/.cache/planarvo;
   * when that cannot be created or written (a service user with no home),
   * $TMPDIR/planarvo-<uid>/programs (a directory only this user can write), else none: kernels
   * are then compiled every time (planarvo_context_cache_dir returns ""). */
  const char* cache_dir;
  int32_t disable_cache; /* non-zero: always compile from source */
  /* Directory of prebuilt program binaries (planarvo_context_export_kernels). When set, the
   * engine loads those and never compiles a kernel, not even as a fallback: what FPGA and DSP
   * runtimes need. A call that needs a program the directory lacks (no manifest, no line for
   * the program and its build options, a binary for another device or driver, a missing file)
   * fails with PLANARVO_ERROR_INVALID_INPUT, and a binary the driver rejects with
   * PLANARVO_ERROR_OPENCL; the message names the program, its build options, the device, the
   * directory, what needs the program and how to export it. The cache options are then unused. */
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
/* The directory of the context's kernel program cache, valid until the context is destroyed;
 * "" when the cache is off: disable_cache, a driver that caches kernels itself, or no usable
 * default location (see cache_dir). With
 * kernel_binaries_dir set the cache is not used whatever this says. "" for a NULL context. */
PLANARVO_API const char* planarvo_context_cache_dir(const planarvo_context* context);
/* Builds every kernel program variant that the library's calls use with their default options
 * for the context's device and writes the binaries into dir (created if missing), with the
 * manifest planarvo-kernels.txt, for later use with kernel_binaries_dir. Lines of the manifest
 * for other devices are kept, so one directory can serve several devices. No option of
 * planarvo_tracker_options, planarvo_roll_pitch_options or the calibration options changes how
 * kernels are built, so these binaries serve every setting of them. */
PLANARVO_API planarvo_status planarvo_context_export_kernels(planarvo_context* context,
                                                             const char* dir);
/* As planarvo_context_export_kernels, but only the variants that the named uses need, a
 * comma-separated list of:
 *   "track"     the tracker (planarvo_tracker_*, planarvo_track_motions);
 *   "calibrate" the camera calibration (planarvo_calibrate_dataset, planarvo_camera_calibrator_*,
 *               planarvo_roll_pitch_*): roll and pitch, then the tracker;
 *   "simulate"  the simulator (planarvo_simulate).
 * uses NULL or "" exports everything, as planarvo_context_export_kernels does; an unknown name
 * is PLANARVO_ERROR_INVALID_ARGUMENT. exported, when not NULL, receives the number of binaries
 * written. */
PLANARVO_API planarvo_status planarvo_context_export_kernels_for(planarvo_context* context,
                                                                 const char* dir, const char* uses,
                                                                 size_t* exported);
/* Builds (or loads) every kernel program now, so that the first frame does not pay for it. */
PLANARVO_API planarvo_status planarvo_context_prepare_kernels(planarvo_context* context);
/* As planarvo_context_prepare_kernels, but only the programs the named uses need (the names of
 * planarvo_context_export_kernels_for; NULL or "": every program). Built programs go to the
 * context's program cache, so another context, or a later run, on the same device loads them. */
PLANARVO_API planarvo_status planarvo_context_prepare_kernels_for(planarvo_context* context, const char* uses);

/* Data sets, bags and the files a run writes: planarvo/dataset.h (part of this header). */
#define PLANARVO_INSIDE_PLANARVO_H
#include "dataset.h" /* include/planarvo/dataset.h */
#undef PLANARVO_INSIDE_PLANARVO_H

/* ------------------------------------------------------------------------------------------ */
/* Simulator                                                                                   */

typedef enum planarvo_motion_profile {
  PLANARVO_MOTION_MIXED = 0,    /* forward and backward driving, turns both ways, turning in
                                   place, stops: everything calibration needs */
  PLANARVO_MOTION_STRAIGHT = 1, /* forwards and backwards along one line */
  PLANARVO_MOTION_CIRCLE = 2,   /* one constant-curvature circle */
  PLANARVO_MOTION_SPIN = 3,     /* turning in place */
  PLANARVO_MOTION_CAR = 4       /* a car: forward driving with turns no tighter than
                                   min_turn_radius, stops, slow reversing; never in place */
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
  int32_t supersampling;      /* samples per pixel along each axis; default 2 (3 in 0.2.0 and before) */
  planarvo_progress_fn progress;
  void* progress_user_data;
  double min_turn_radius;     /* PLANARVO_MOTION_CAR: the tightest turn, metres; default 0 (only
                                 max_turn_rate limits it). Read only when struct_size covers it. */
  /* Real-camera geometry; each read only when struct_size covers it. */
  double readout_time;        /* rolling shutter: seconds from the first row's read to the last's,
                                 at most 1 / fps; written into camera.yaml as
                                 rolling_shutter_readout; default 0 (global shutter). The camera's
                                 own rolling_shutter_readout is replaced by it. */
  double exposure_time;       /* seconds each row integrates the moving scene before it is read
                                 (motion blur), at most 1 / fps; default 0 (instantaneous) */
  /* Light fixed to the camera (a real camera's own lamp, its reflection, the robot's shadow),
   * each 0 = none (the default). Read only when struct_size covers them. */
  double lamp_falloff;        /* a lamp beside the lens: the darkest image corner gets 1 - this
                                 of the brightest point's light; 0..0.95 */
  double reflection;          /* the lamp's reflection on a glossy floor: peak grey levels added
                                 (a bright spot that saturates); 0..1000 */
  double shadow;              /* the robot's shadow over the image's bottom: fraction of light
                                 taken; 0..0.95 */
  /* A body on its suspension (a car) and a knock to the camera's mounting; each read only when
   * struct_size covers it. The camera turns with the body relative to the local ground plane,
   * R_plane_body = Rx(roll) Ry(pitch) about the robot frame's origin; data sets then get
   * plane.txt, the true attitude per frame (the format of planarvo track --plane-out). */
  double lean;                /* body roll per yaw rate, seconds (radians per rad/s, or degrees
                                 per degree/s); the paper's car about -0.07; default 0 */
  double bumps;               /* speed bumps every 10 m driven (2.5 m long): peak body pitch,
                                 radians, both signs over one bump; default 0 */
  double knock_time;          /* seconds; default INFINITY (no knock). From then on the mounting
                                 is off by: */
  double knock_roll, knock_pitch; /* radians */
  double knock_z;             /* metres; the data set gets extrinsics_knocked.yaml */
  int32_t accept_unusual_extrinsics; /* as planarvo_tracker_options': non-zero lets extrinsics
                                        outside the plausible ranges through; default 0 */
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

/* ------------------------------------------------------------------------------------------ */
/* Dense planar visual odometry                                                                */

/* Tracks each frame against a keyframe by dense alignment through the ground-plane homography
 * (the paper's section 4), coarse to fine, estimating the robot's planar motion and an affine
 * brightness change. Owns its device buffers; uses the context it was created with, which must
 * outlive it. Thread safety: one thread at a time (its context too). */
typedef struct planarvo_tracker planarvo_tracker;

typedef struct planarvo_tracker_options {
  size_t struct_size;
  int32_t levels;             /* pyramid levels; default 4 */
  int32_t finest_level;       /* finest level tracked, 0 = full resolution; default -1: see
                                 level0_subsample */
  int32_t max_iterations;     /* cap on alignment steps per level; 0 = the per-level defaults */
  double keyframe_overlap;    /* a new keyframe when the overlap falls below this; default 0.7 */
  int32_t estimate_brightness;/* non-zero: estimate gain and offset per frame; default 1 */
  /* The finest level on one pixel per B x B block (a jittered grid per keyframe), solved with the
   * level above's estimate. finest_level -1: the coarsest level at least 320 px wide (at 1/4 when
   * the level below it is subsampled), then that level at B, 0 meaning 3 (640x480: level 1 at 1/4,
   * level 0 at 1/9; 320x240: level 0 on every pixel). Explicit finest_level: 0 is every pixel. 1:
   * every pixel, and the level above it too; 2..8: B. Unread (so 0) for older struct_size. */
  int32_t level0_subsample;
  /* A known flat field (NULL or "" = learn the light fixed to the camera from the frames, the
   * default): an image file of the camera's relative brightness per pixel of the distorted camera
   * image, brightest = 1 (like DSO's vignette.png), any 8- or 16-bit grey format OpenCV reads
   * (16-bit divided by 65535, 8-bit by 255, then the image by its maximum), the camera's size,
   * no zero or non-finite pixel. Read by planarvo_tracker_create (PLANARVO_ERROR_INVALID_INPUT
   * naming the file otherwise) and used from the first frame, without learning. The string need
   * not outlive the call. planarvo_tracker_save_flat_field writes such a file. Unread (so NULL)
   * for older struct_size. */
  const char* flat_field;
  /* The local plane (the paper's section 6.4): non-zero estimates the body's roll and pitch
   * relative to the local ground plane with every frame's motion (planarvo_track_result.roll,
   * .pitch), for a car whose body leans in turns and pitches over bumps; the extrinsics are then
   * the camera's mounting on the body at rest. Default 0 (a rigid body). local_plane_prior_sigma:
   * the standard deviation, radians, of the prior that holds the attitude at the mounting where the
   * images do not say otherwise; default 0.008727 (0.5 degree); must be positive and finite. Unread
   * (so off) for older struct_size. */
  int32_t local_plane;
  double local_plane_prior_sigma;
  /* Online recalibration, with local_plane: a step in the body's attitude that persists (the camera's
   * mounting knocked, a bracket bent) as opposed to the body's lean in turns and over bumps, which
   * passes. A planarvo_mounting_response: PLANARVO_MOUNTING_RECALIBRATE (the default) reports the
   * change in the frame that confirms it (planarvo_track_result.mounting_changed) and tracks on with
   * the mounting changed by it (the camera turned about its centre: its height kept);
   * PLANARVO_MOUNTING_REPORT only reports it and keeps the mounting given; PLANARVO_MOUNTING_IGNORE
   * does not watch. mounting_min_step: the smallest change reported, radians; default 0.01745 (1
   * degree); positive and finite. Unread (so RECALIBRATE, 1 degree) for older struct_size. */
  int32_t on_mounting_change;
  double mounting_min_step;
  /* Extrinsics outside what a camera on a vehicle can be are refused with
   * PLANARVO_ERROR_INVALID_ARGUMENT naming the value and its likely unit mistake: x or y over 20 m,
   * a height over 5 m, an angle over a turn (2 pi; degrees given as radians). Non-zero lets an
   * unusual rig through. Default 0; unread (so 0) for older struct_size. */
  int32_t accept_unusual_extrinsics;
} planarvo_tracker_options;

typedef enum planarvo_mounting_response {
  PLANARVO_MOUNTING_IGNORE = 0,
  PLANARVO_MOUNTING_REPORT = 1,
  PLANARVO_MOUNTING_RECALIBRATE = 2
} planarvo_mounting_response;

typedef enum planarvo_track_status {
  PLANARVO_TRACK_FIRST = 0,    /* the first frame: it becomes the keyframe, no motion */
  PLANARVO_TRACK_OK = 1,
  PLANARVO_TRACK_DEGRADED = 2, /* tracked, but doubtful: reason says why */
  PLANARVO_TRACK_LOST = 3      /* not tracked: motion is a prediction (constant velocity or 0) */
} planarvo_track_status;

typedef struct planarvo_track_result {
  size_t struct_size;
  planarvo_track_status status;
  const char* reason;         /* why DEGRADED or LOST, "" otherwise; a static string */
  planarvo_se2 motion;        /* this frame's robot pose in the previous frame's robot frame */
  double covariance[9];       /* of motion (x, y, theta), row-major; large when LOST */
  planarvo_se2 pose;          /* the robot's pose relative to the first frame */
  int32_t iterations[8];      /* alignment steps per pyramid level (index = level) */
  int32_t levels_used;
  double final_cost;          /* mean robust cost per pixel at the finest level */
  double inlier_fraction;     /* residuals within the robust threshold */
  double overlap;             /* keyframe pixels seen in this frame */
  int32_t keyframe;           /* non-zero when this frame became the keyframe */
  double ms;                  /* engine time: upload, undistortion, pyramid and tracking */
  /* With planarvo_tracker_options.local_plane: the body's rotation relative to the local ground
   * plane at this frame, R_plane_body = Rx(roll) Ry(pitch), radians, and its covariance (roll,
   * pitch; row-major). A LOST frame keeps the last attitude with the prior's covariance. Zero
   * otherwise. Written only when struct_size covers them. */
  double roll, pitch;
  double attitude_covariance[4];
  /* With planarvo_tracker_options.local_plane: the mounting this frame was tracked with (the
   * extrinsics given, or the last recalibration's). mounting_changed is non-zero when this frame
   * confirmed a change of the mounting: mounting_change_time is when it began (seconds, a frame's
   * timestamp), mounting_step the step in the body's roll and pitch (radians, the attitude as roll
   * and pitch above), the turn about the body's vertical that came with it (radians, from the
   * direction of travel: a car's is straight ahead) and the camera's height (metres), with their
   * standard deviations, and changed_mounting the mounting it implies: the extrinsics with the
   * camera turned about its centre by the steps and raised by the height's (in use from the next
   * frame with PLANARVO_MOUNTING_RECALIBRATE). The height is watched only with wheel odometry
   * (planarvo_tracker_odometry): the images of a plane fix it only with the scale of the motion. A
   * sigma is NaN when that part was not judged. Written only when struct_size covers them. */
  planarvo_extrinsics mounting;
  /* Non-zero when the images separated the attitude from the motion (its variance below half the
   * prior's); 0 while the car has not moved since the start (the attitude holds at the mounting)
   * and on LOST frames. */
  int32_t attitude_observed;
  int32_t mounting_changed;
  /* Non-zero with mounting_changed when this is the refinement of the last change taken into use:
   * what was left of it, measured over the first frames tracked with it. */
  int32_t mounting_refinement;
  double mounting_change_time;
  double mounting_step[4];        /* roll, pitch, yaw, z */
  double mounting_step_sigma[4];
  planarvo_extrinsics changed_mounting;
} planarvo_track_result;

PLANARVO_API void planarvo_tracker_options_init(planarvo_tracker_options* options);
/* camera: the distorted camera the frames come from; extrinsics: the camera on the robot.
 * options may be NULL. PLANARVO_ERROR_INVALID_ARGUMENT for extrinsics that are not finite, a
 * height z <= 0, or angles with which no part of the image looks below the horizon (the camera
 * would not see the ground: degrees given for radians, for example). */
PLANARVO_API planarvo_status planarvo_tracker_create(planarvo_context* context,
                                                     const planarvo_camera* camera,
                                                     const planarvo_extrinsics* extrinsics,
                                                     const planarvo_tracker_options* options,
                                                     planarvo_tracker** tracker);
PLANARVO_API void planarvo_tracker_destroy(planarvo_tracker* tracker);
/* Tracks one frame (any planarvo_pixel_format; colour is converted to grey). A frame that cannot
 * be tracked (wrong size, black, saturated, textureless, after a gap) is not an error: the call
 * returns PLANARVO_OK with status LOST or DEGRADED, and tracking recovers on the next good frame.
 * Timestamps (seconds) should increase; one that does not is not an error: at best DEGRADED. */
PLANARVO_API planarvo_status planarvo_tracker_track(planarvo_tracker* tracker,
                                                    const planarvo_image* image, double timestamp,
                                                    planarvo_track_result* result);
/* Forgets the keyframe and the pose: the next frame is FIRST again. */
PLANARVO_API planarvo_status planarvo_tracker_reset(planarvo_tracker* tracker);
/* The wheel odometry's pose (any fixed odometry frame; metres, radians) at the time of the next
 * frame to be tracked, given before planarvo_tracker_track: with the local plane, the distances
 * tracked are compared with the wheels' to notice the camera's height changed. Frames given none
 * are left out of that comparison. A pose that is not finite: PLANARVO_ERROR_INVALID_ARGUMENT. */
PLANARVO_API planarvo_status planarvo_tracker_odometry(planarvo_tracker* tracker, const planarvo_se2* pose);
/* Writes the photometric model in use (the learnt one, or the flat field given) as a flat-field
 * file that planarvo_tracker_options.flat_field reads back: a 16-bit grey PNG of the camera's size,
 * the relative brightness per distorted camera pixel (brightest 65535), written complete or not at
 * all. Pixels where the model has no value (a saturated reflection, no undistorted source) take
 * the nearest pixel's value. PLANARVO_ERROR_FAILED when no model has been learnt yet: the model
 * stays the identity until enough frames in motion show light fixed to the camera (an evenly lit
 * camera never leaves it). PLANARVO_ERROR_IO when the file cannot be written. */
PLANARVO_API planarvo_status planarvo_tracker_save_flat_field(planarvo_tracker* tracker, const char* path);
/* The last tracked frame's residuals against the keyframe it was aligned with, for an outlier
 * overlay (the paper's Figure 20; planarvo plot outliers draws one). Per keyframe pixel of pyramid
 * `level` (0 = full resolution; every pixel of the level, whatever subsampling tracking used),
 * row-major, width x height of that level, in the keyframe's undistorted image:
 *   residual   r = gain * I_live(w(p)) + bias - I_keyframe(p), grey levels, at the final
 *              alignment (its warp w for that level, its gain and bias); 0 where invalid;
 *   weight     the Huber weight: 1 for |r| <= k, k / |r| (below 1) for the pixels the robust norm
 *              down-weighted, 0 where invalid (the keyframe pixel has no valid image, or its warp
 *              leaves the live frame's valid pixels);
 *   intensity  the keyframe's undistorted intensity (0..255), NaN where it has none.
 * k (*threshold, grey levels) is the Huber threshold the tracker used at the finest level it
 * tracked, at every level asked: 2 x the robust scale in use there (1.4826 x the median |r| of the
 * frame's first pass at that level, or the previous frame's scale when within 25 % of it).
 * Any of the arrays and of width, height, threshold may be NULL; with an array, capacity must be
 * at least width x height (else PLANARVO_ERROR_BUFFER_TOO_SMALL, with *width and *height set):
 * call with NULL arrays to ask the size. One extra pass on the device when asked (the first call
 * also builds its kernel); asking again for the same level before the next frame reads it again.
 * A frame that became the keyframe is still compared with the keyframe it was aligned with. A LOST
 * frame whose alignment ran (reason "images do not match" or a brightness change) gives its
 * residuals at that alignment; one that was not aligned (wrong size, too few valid pixels, no
 * texture, diverged) gives PLANARVO_ERROR_FAILED. PLANARVO_ERROR_INVALID_ARGUMENT before any frame
 * was tracked after the first (or after a reset), or for a level outside 0..levels-1. */
PLANARVO_API planarvo_status planarvo_tracker_residuals(planarvo_tracker* tracker, int32_t level,
                                                        float* residual, float* weight,
                                                        float* intensity, size_t capacity,
                                                        int32_t* width, int32_t* height,
                                                        double* threshold);

/* Accuracy of estimated frame-to-frame motions against true ones (see planarvo track). */
typedef struct planarvo_motion_accuracy {
  size_t struct_size;
  int32_t intervals;        /* compared */
  double distance;          /* metres travelled */
  double slope_linear;      /* fitted slope of estimated vs true forward speed */
  double slope_angular;     /* ... and angular speed */
  double rms_translation;   /* per interval, metres */
  double max_translation;
  double rms_rotation;      /* radians */
  int32_t gross_errors;     /* intervals with a translation error over the threshold */
  double endpoint_error;    /* metres */
  double endpoint_drift;    /* endpoint_error / distance */
  double endpoint_heading;  /* radians */
} planarvo_motion_accuracy;

/* estimated[i], truth[i]: motion over interval i; dt[i] its duration; valid: NULL to count every
 * interval (what planarvo track reports first: a Lost frame's motion is the tracker's prediction
 * and part of the trajectory), or per-interval flags (0: left out of the per-interval figures,
 * e.g. to report one status apart; the end point always composes every interval). */
PLANARVO_API planarvo_status planarvo_evaluate_motions(const planarvo_se2* estimated,
                                                       const planarvo_se2* truth, const double* dt,
                                                       const int32_t* valid, size_t count,
                                                       double gross_threshold,
                                                       planarvo_motion_accuracy* accuracy);

/* A least-squares line y = slope x + offset; slope_sigma its standard error from the residual
 * scatter (infinite with fewer than 3 samples or no spread in x); r2 the share of the variance
 * it explains. */
typedef struct planarvo_line_fit {
  double slope, offset, slope_sigma, r2;
  int32_t samples;
} planarvo_line_fit;

/* The vehicle's lean (the paper's Figure 18) from a drive tracked with the local plane: the body's
 * roll against the yaw rate (slope in seconds: radians per rad/s, or degrees per degree/s; the
 * paper's car -0.07) and its pitch against the longitudinal acceleration (radians per m/s^2). */
typedef struct planarvo_body_lean {
  size_t struct_size;
  planarvo_line_fit roll_per_yaw_rate;
  planarvo_line_fit pitch_per_acceleration;
} planarvo_body_lean;

/* Fits planarvo_body_lean: frame k has timestamps[k], motions[k] (over the interval from frame
 * k-1; motions[0] is unused), roll[k] and pitch[k] (planarvo_track_result's); use[k] 0 leaves
 * the frame out (NULL: all of them; leave LOST frames out). The yaw rate at a frame is the mean
 * of its two intervals', the acceleration the forward speed's central difference. The slopes'
 * sigma are lower bounds when the attitudes' own errors dominate the scatter (they are correlated
 * from frame to frame). */
PLANARVO_API planarvo_status planarvo_fit_body_lean(const double* timestamps, const planarvo_se2* motions,
                                                    const double* roll, const double* pitch, const int32_t* use,
                                                    size_t count, planarvo_body_lean* lean);

/* Pose graphs, motion pairs and the calibrations: planarvo/calibration.h (part of this header). */
#define PLANARVO_INSIDE_PLANARVO_H
#include "calibration.h" /* include/planarvo/calibration.h */
#undef PLANARVO_INSIDE_PLANARVO_H

/* The floor mosaic: planarvo/mosaic.h (part of this header). */
#define PLANARVO_INSIDE_PLANARVO_H
#include "mosaic.h" /* include/planarvo/mosaic.h */
#undef PLANARVO_INSIDE_PLANARVO_H

#ifdef __cplusplus
}
#endif

#endif /* PLANARVO_PLANARVO_H */
