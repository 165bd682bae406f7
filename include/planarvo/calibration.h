/*
 * planarvo: pose graphs, motion pairs, the graph calibrations and the camera calibration from
 * images. Part of planarvo/planarvo.h, which includes it where the types it uses are defined:
 * include <planarvo/planarvo.h>, not this file.
 */
#ifndef PLANARVO_CALIBRATION_H
#define PLANARVO_CALIBRATION_H

#ifndef PLANARVO_INSIDE_PLANARVO_H
#error "include <planarvo/planarvo.h>, not <planarvo/calibration.h>"
#endif

/* ------------------------------------------------------------------------------------------ */
/* Graph optimisation and calibration (no OpenCL device is used)                               */

/* Receives text lines (an iteration table, notes) from long calls that take one. */
typedef void (*planarvo_log_fn)(void* user_data, const char* line);

typedef struct planarvo_solver_summary {
  size_t struct_size;
  int32_t converged;        /* non-zero: stopped on a tolerance, not a cap or a failure */
  char termination[256];    /* why it stopped, with the numbers */
  int32_t iterations;       /* Levenberg-Marquardt iterations */
  int32_t factorizations;   /* numeric Cholesky factorisations (CHOLMOD) */
  double initial_chi2, final_chi2; /* sum of e' Omega e over the factors (robustified where a
                                      robust loss is used) */
  double seconds;
} planarvo_solver_summary;

typedef enum planarvo_posegraph_init {
  PLANARVO_POSEGRAPH_INIT_NONE = 0,          /* start from the file's poses */
  PLANARVO_POSEGRAPH_INIT_ROTATION_FIRST = 1 /* orientations first (LAGO), then positions */
} planarvo_posegraph_init;

typedef struct planarvo_posegraph_options {
  size_t struct_size;
  int32_t max_iterations;           /* default 100 */
  planarvo_posegraph_init init;     /* default PLANARVO_POSEGRAPH_INIT_NONE */
  planarvo_log_fn log;              /* the iteration table; NULL for none */
  void* log_user_data;
} planarvo_posegraph_options;

PLANARVO_API void planarvo_posegraph_options_init(planarvo_posegraph_options* options);
/* Optimises a g2o-format 2-D pose graph (VERTEX_SE2, EDGE_SE2, FIX; g2o's error convention; the
 * first vertex held fixed) read from in_path, and writes it to out_path (NULL: not written).
 * PLANARVO_ERROR_FAILED when the solver did not converge (summary says why; out_path is still
 * written). */
PLANARVO_API planarvo_status planarvo_posegraph_optimize(const char* in_path, const char* out_path,
                                                         const planarvo_posegraph_options* options,
                                                         planarvo_solver_summary* summary);

/* One interval of planar motion: the sensor's own motion (its frame at the interval's start;
 * translation in metres for a metric sensor, in units of the camera height for the tracker run
 * at height 1), optionally the robot's motion from wheel odometry and a direction label.
 * Versioned like the option structs: set struct_size with planarvo_motion_pair_init. In an array
 * the stride between elements is pairs[0].struct_size, and every element has the same one, so an
 * array built against an older header keeps working (its missing fields take their defaults). */
typedef struct planarvo_motion_pair {
  size_t struct_size;       /* sizeof(planarvo_motion_pair) */
  double interval;          /* seconds */
  planarvo_se2 sensor;
  int32_t has_odometry;
  planarvo_se2 odometry;
  int32_t has_direction;
  int32_t direction;        /* +1 forwards, -1 backwards, 0 no linear motion */
  /* Covariances of the motions, 3x3 row-major, order x y theta, in the motions' units (the
   * sensor's units, metres for odometry; radians): of the right perturbation xi in motion*exp(xi),
   * as the tracker reports it. Without one (has_ 0, the default) planarvo_calibrate uses the
   * options' noise model (sensor_sigma_..., odometry_sigma_...). */
  int32_t has_sensor_covariance;
  double sensor_covariance[9];
  int32_t has_odometry_covariance; /* needs has_odometry */
  double odometry_covariance[9];
} planarvo_motion_pair;

/* The camera's own motion (the sensor motion of the graph calibration, docs/conventions.md "Sensor
 * motions and the calibration model") from a robot motion tracked with extrinsics e: the motion of
 * the ground point below the camera, turned by its yaw, in units of its height, as tracking with
 * x = y = 0, z = 1, yaw = 0 and e's roll and pitch measures it. robot_covariance and
 * sensor_covariance (3x3 row-major, right perturbations) may be NULL. PLANARVO_ERROR_INVALID_ARGUMENT
 * unless e->z > 0. */
PLANARVO_API planarvo_status planarvo_sensor_motion(const planarvo_extrinsics* e, const planarvo_se2* robot_motion,
                                                   const double* robot_covariance, planarvo_se2* sensor_motion,
                                                   double* sensor_covariance);

/* Zeroes *pair (no odometry, direction or covariances) and sets its struct_size. */
PLANARVO_API void planarvo_motion_pair_init(planarvo_motion_pair* pair);
/* Writes count motion pairs (elements pairs[0].struct_size bytes apart) as the CSV that
 * planarvo_motion_pairs_load reads. Every pair must have the same columns (all with odometry or
 * none, all with a direction label or none); covariances are not written. */
PLANARVO_API planarvo_status planarvo_motion_pairs_save(const char* path, const planarvo_motion_pair* pairs,
                                                        size_t count);

/* Reads a motion-pair CSV (columns interval_s, [odo_dx, odo_dy, odo_dtheta,] sensor_dx, sensor_dy,
 * sensor_dtheta[, direction]; without a direction column the odometry's forward motion gives it).
 * Call with pairs = NULL for the count, then with capacity >= count and pairs[0].struct_size set
 * (planarvo_motion_pair_init): every element is written at that stride, no further than that
 * size, with that struct_size and no covariances (the file has none). */
PLANARVO_API planarvo_status planarvo_motion_pairs_load(const char* path, planarvo_motion_pair* pairs,
                                                        size_t capacity, size_t* count);

typedef enum planarvo_calibration_method {
  PLANARVO_CALIBRATE_ODOMETRY = 0,    /* x, y, scale (height), yaw against wheel odometry */
  PLANARVO_CALIBRATE_NONHOLONOMIC = 1 /* x, yaw from the nonholonomic constraint; y from labels */
} planarvo_calibration_method;

typedef enum planarvo_robust_loss {
  PLANARVO_ROBUST_LOSS_NONE = 0,   /* plain least squares */
  PLANARVO_ROBUST_LOSS_HUBER = 1,
  PLANARVO_ROBUST_LOSS_CAUCHY = 2,
  PLANARVO_ROBUST_LOSS_TUKEY = 3
} planarvo_robust_loss;

typedef struct planarvo_calibration_options {
  size_t struct_size;
  planarvo_calibration_method method;  /* default ODOMETRY */
  int32_t fix_scale;        /* hold the scale at fixed_scale (metric sensor: 1; a measured camera
                               height); the nonholonomic method always needs it held */
  double fixed_scale;       /* default 1 */
  int32_t has_initial;      /* use initial (x, y, scale, yaw) instead of the built-in initialisation */
  double initial[4];
  int32_t velocity_form;    /* nonholonomic: the paper's velocity form instead of the exact arc */
  int32_t max_iterations;   /* default 100 */
  planarvo_log_fn log;      /* the solver's iteration table; NULL for none */
  void* log_user_data;
  /* The noise model: standard deviations of a motion's (x, y, theta) for pairs that carry no
   * covariance. Translation sqrt(floor^2 + (relative * |t|)^2), rotation
   * sqrt(theta^2 + (relative * |dtheta|)^2): relative per unit of travel and per radian turned.
   * Sensor in the sensor's units (those of its motions), odometry in metres; radians. All finite
   * and >= 0; the theta ones > 0, and floor and relative not both 0. */
  double sensor_sigma_relative;   /* default 0.01 */
  double sensor_sigma_floor;      /* default 1e-4 (sensor units) */
  double sensor_sigma_theta;      /* default 1e-3 rad */
  double odometry_sigma_relative; /* default 0.01 */
  double odometry_sigma_floor;    /* default 1e-4 m */
  double odometry_sigma_theta;    /* default 2e-3 rad */
  /* Gross errors (failed scan matches, tracking glitches): a first solve with the robust loss,
   * then gating: a pair whose normalised squared residual exceeds gate_sigma^2 (times the
   * residuals' own robust variance factor where that exceeds 1) loses its sensor motion, and the
   * rest is re-solved by plain least squares, repeated while the gate drops more (outliers counts
   * them). gate_sigma 0: no gating; the loss then stays on in the one solve. */
  planarvo_robust_loss loss;      /* default PLANARVO_ROBUST_LOSS_CAUCHY */
  double loss_scale;              /* where the loss starts, in standard deviations; default 3, > 0 */
  double gate_sigma;              /* default 5; >= 0 */
  /* Direction labels of pairs with odometry but no label (the nonholonomic method uses them): 0
   * (no linear motion) when the odometry's forward speed is below this, else its sign. m/s,
   * default 1e-3; >= 0. */
  double still_speed;
  /* Odometry method, pairs without an odometry covariance: 1 fits the odometry's noise model to the
   * calibration's own residuals (per component along travel, sideways and in heading: a constant, a
   * part per metre and a part per radian) and solves again, so the covariance reflects the
   * odometry's actual noise; 0 keeps the odometry_sigma_* model. Default -1: the workflow's own
   * choice, 1 where the camera's motions are tracked from frames (planarvo_calibrate_dataset, the
   * camera calibrator: the camera's motions are far more precise than wheel odometry, so the
   * residuals measure the odometry) and 0 for motion pairs given (planarvo_calibrate: a sensor of
   * unknown precision). Any other negative value is -1, any positive 1. */
  int32_t estimate_odometry_noise;
} planarvo_calibration_options;

typedef struct planarvo_calibration_result {
  size_t struct_size;
  double value[4];          /* x (m), y (m), scale (camera height m, or the fixed scale), yaw (rad) */
  double covariance[16];    /* row-major, order x y scale yaw; zero rows when not estimated */
  int32_t estimated[4];     /* the method estimated this parameter */
  int32_t observable[4];    /* ... and the data determine it */
  int32_t ambiguous;        /* nonholonomic without labels: (-x, yaw + pi) fits as well */
  int32_t outliers;         /* samples rejected as gross errors */
  int32_t ok;               /* converged, every estimated parameter observable, not ambiguous */
  char unobservable_reason[512];
  planarvo_solver_summary summary; /* the final solve's */
  int32_t total_iterations; /* Levenberg-Marquardt iterations over all solves (start, robust, gated) */
  double total_seconds;     /* the whole calibration */
  double variance_factor;   /* a-posteriori max(1, chi2/dof) of the final fit: covariance includes it */
} planarvo_calibration_result;

PLANARVO_API void planarvo_calibration_options_init(planarvo_calibration_options* options);
/* Calibrates from an array of count motion pairs (stride pairs[0].struct_size). Returns
 * PLANARVO_ERROR_FAILED (with the reason as the message) when the result is not ok: unobservable,
 * ambiguous or not converged; the result is filled in either case. */
PLANARVO_API planarvo_status planarvo_calibrate(const planarvo_motion_pair* pairs, size_t count,
                                                const planarvo_calibration_options* options,
                                                planarvo_calibration_result* result);
/* A motion pair's residual at the calibration's estimate, as the odometry method weighs it: the
 * robot's motion between the pair's poses eliminated exactly, d = the odometry's (x, y, theta) less
 * the sensor's motion mapped into the robot frame (robot frame at the interval's start; m, m, rad,
 * the angle wrapped), with the covariance the calibration gave it (the odometry's, fitted or the
 * model's, plus the sensor's carried into the robot frame) and chi2 = d^T covariance^-1 d. Summed
 * over the pairs, the solver's chi2 at the estimate. */
typedef struct planarvo_pair_residual {
  int32_t has_odometry;   /* 0: the pair has no odometry (d, covariance and chi2 are 0) */
  int32_t outlier;        /* gated out as a gross error (its sensor motion not used) */
  double d[3];
  double covariance[9];   /* row-major */
  double chi2;
} planarvo_pair_residual;

/* The wheel odometry's noise model the calibration used for pairs without a covariance of their
 * own: fitted to its residuals (estimate_odometry_noise), or not. Variance of component c (x along
 * the motion's start frame, y, theta): variance[3c] + variance[3c + 1] |t|^2 + variance[3c + 2]
 * theta^2 (m^2, m^2 per m^2 of travel, per rad^2 of turn; rad^2 ... for theta). */
typedef struct planarvo_odometry_noise {
  int32_t fitted;         /* 0: the options' odometry_sigma_* model was used (variance all 0 here) */
  double variance[9];
} planarvo_odometry_noise;

/* planarvo_calibrate, and what plots draw: per pair its residual at the estimate (residuals: count
 * elements, or NULL) and the odometry's noise model (noise, or NULL). */
PLANARVO_API planarvo_status planarvo_calibrate_residuals(const planarvo_motion_pair* pairs, size_t count,
                                                          const planarvo_calibration_options* options,
                                                          planarvo_calibration_result* result,
                                                          planarvo_pair_residual* residuals,
                                                          planarvo_odometry_noise* noise);
/* Writes a motion-pair calibration as extrinsics.yaml (docs/formats.md): x, y, yaw and z = the
 * scale (the camera height), with their covariance and which were estimated; with metric_sensor
 * non-zero (the pairs' sensor measured metres, e.g. a laser scan matcher) z is 0, not estimated.
 * Roll and pitch are 0, not estimated (they come from images). The method's sentence, and notes as
 * given (NULL: none). PLANARVO_ERROR_IO when the file cannot be written. */
PLANARVO_API planarvo_status planarvo_calibration_save(const char* path, const planarvo_calibration_result* result,
                                                       planarvo_calibration_method method, int32_t metric_sensor,
                                                       const char* notes);

/* ------------------------------------------------------------------------------------------ */
/* Camera calibration from images (the paper's sections 5.1 and 5.2)                           */

/* Why a calibration stage did not give an answer. */
typedef enum planarvo_calibration_status {
  PLANARVO_CALIBRATION_OK = 0,
  PLANARVO_CALIBRATION_TOO_LITTLE_TEXTURE = 1, /* the frames could not be tracked */
  PLANARVO_CALIBRATION_TOO_LITTLE_MOTION = 2,  /* the camera did not move enough for roll and pitch */
  PLANARVO_CALIBRATION_UNOBSERVABLE = 3,       /* the drive does not determine x, y, height or yaw */
  PLANARVO_CALIBRATION_FAILED = 4              /* anything else; the reason says what */
} planarvo_calibration_status;

/* Roll and pitch from images alone (section 5.1): frames are fed until a local map of keyframes
 * is complete, then the keyframe motions and the camera's tilt are aligned jointly. No odometry,
 * no targets, any motion but standing still. */
typedef struct planarvo_roll_pitch planarvo_roll_pitch;

typedef struct planarvo_roll_pitch_options {
  size_t struct_size;
  double initial_roll, initial_pitch; /* start (radians); default 0, 0: looking straight down */
  int32_t max_frames;     /* frames used, counted from the first in which the camera moves;
                             default 0: until the map has max_keyframes keyframes */
  int32_t min_keyframes;  /* default 5 */
  int32_t max_keyframes;  /* default 12 */
  double keyframe_overlap;/* a frame joins the map below this overlap with the last keyframe;
                             default 0.9 */
  int32_t search;         /* non-zero: a coarse search over the angles when the alignment from
                             the start does not converge; default 1 */
} planarvo_roll_pitch_options;

typedef struct planarvo_roll_pitch_result {
  size_t struct_size;
  planarvo_calibration_status status; /* OK, TOO_LITTLE_TEXTURE, TOO_LITTLE_MOTION or FAILED */
  char reason[512];        /* "" when OK */
  double roll, pitch;      /* radians */
  double covariance[4];    /* of (roll, pitch), row-major, rad^2 */
  int32_t frames_used, keyframes, pairs;
  double seconds;          /* picking keyframes and the joint alignment */
} planarvo_roll_pitch_result;

PLANARVO_API void planarvo_roll_pitch_options_init(planarvo_roll_pitch_options* options);
/* camera: the distorted camera the frames come from. options may be NULL. */
PLANARVO_API planarvo_status planarvo_roll_pitch_create(planarvo_context* context, const planarvo_camera* camera,
                                                        const planarvo_roll_pitch_options* options,
                                                        planarvo_roll_pitch** estimator);
PLANARVO_API void planarvo_roll_pitch_destroy(planarvo_roll_pitch* estimator);
/* Feeds one frame; *complete (may be NULL) becomes non-zero once the map is complete (later frames
 * are ignored). A frame of the wrong size or without texture is counted and skipped. */
PLANARVO_API planarvo_status planarvo_roll_pitch_add_frame(planarvo_roll_pitch* estimator,
                                                           const planarvo_image* image, double timestamp,
                                                           int32_t* complete);
/* Estimates from the frames fed so far. PLANARVO_ERROR_FAILED (the reason as the message) when
 * the status is not OK; the result is filled in either case. */
PLANARVO_API planarvo_status planarvo_roll_pitch_estimate(planarvo_roll_pitch* estimator,
                                                          planarvo_roll_pitch_result* result);

/* The whole calibration: roll and pitch from the first frames with enough motion, the sequence
 * tracked with them, then x, y, height and yaw from the graph calibration, against wheel
 * odometry or from the nonholonomic constraint with direction labels and a given height. */
/* Where the calibration gets the rolling shutter's readout time (docs/outputs.md, "Rolling-shutter
 * cameras"). */
typedef enum planarvo_readout_source {
  /* planarvo_calibrate_dataset estimates it when the data set's camera gives none (no
   * rolling_shutter_readout in camera.yaml or the bag's --camera file, none set with
   * planarvo_dataset_set_readout); a calibrator takes its camera's as it is. */
  PLANARVO_READOUT_IF_UNKNOWN = 0,
  PLANARVO_READOUT_CAMERA = 1,   /* the camera's as it is (0: a global shutter); the default */
  PLANARVO_READOUT_ESTIMATE = 2  /* estimated from the drive whatever the camera says: within
                                    0.6 ms of the truth on 20-s simulated 640x480 drives
                                    (docs/outputs.md) */
} planarvo_readout_source;

typedef struct planarvo_camera_calibration_options {
  size_t struct_size;
  planarvo_calibration_method method; /* default ODOMETRY */
  double height;            /* the camera height in metres when known (then held, not estimated);
                               0 = estimate it (odometry method only); default 0 */
  int32_t roll_pitch_frames;/* frames for roll and pitch (planarvo_roll_pitch_options.max_frames);
                               default 0 */
  int32_t has_initial;      /* non-zero: start from `initial` (roll and pitch for section 5.1,
                               x, y, z, yaw for the graph) */
  planarvo_extrinsics initial;
  int32_t estimate_roll_pitch; /* default 1; 0: roll and pitch are initial's (has_initial needed) */
  /* The graph's noise model and robustness, and the tracker's options: NULL for the defaults. */
  const planarvo_calibration_options* graph;
  const planarvo_tracker_options* tracker;
  planarvo_progress_fn progress;
  void* progress_user_data;
  planarvo_readout_source readout; /* default PLANARVO_READOUT_CAMERA */
  /* As planarvo_tracker_options': non-zero lets an `initial` or a `height` outside the plausible
   * ranges through (a height of 178.7 is refused: millimetres?). Default 0; unread (so 0) for
   * older struct_size. */
  int32_t accept_unusual_extrinsics;
} planarvo_camera_calibration_options;

typedef struct planarvo_camera_calibration_result {
  size_t struct_size;
  planarvo_calibration_status status;
  char reason[512];          /* "" when OK: what failed, and what would fix it */
  planarvo_extrinsics extrinsics;
  double covariance[36];     /* 6x6 row-major, order x y z roll pitch yaw; zero rows and columns
                                for parameters not estimated */
  int32_t estimated[6];      /* this run estimated the parameter (else it was given) */
  int32_t observable[6];     /* estimated and determined by the data */
  planarvo_roll_pitch_result roll_pitch;    /* stage 1 */
  planarvo_calibration_result graph;        /* stage 3 (x, y, scale = height, yaw) */
  int32_t frames, frames_ok, frames_degraded, frames_lost, samples;
  double tracking_median_ms; /* engine time per frame in stage 2 */
  /* Wall seconds: waiting for images (data sets: each is decoded while the one before is
   * processed, so this is the decoding the processing did not hide), roll and pitch, tracking,
   * graph, all. */
  double seconds_decode, seconds_roll_pitch, seconds_tracking, seconds_graph, seconds_total;
  /* The rolling shutter's readout time, seconds: what roll and pitch and the tracking used
   * (readout), and its estimate from the drive with its standard deviation when one was made
   * (readout_evaluations > 0: the candidate readouts tracked, over readout_frames frames).
   * readout is the estimate, or 0 when the estimate is within 2 sigma of 0 (a global shutter).
   * readout_reason: why the estimate failed ("" when it did not; the camera's readout was used),
   * for example a drive too slow to shear the images. */
  double readout, readout_estimate, readout_sigma;
  int32_t readout_evaluations, readout_frames;
  char readout_reason[256];
  double seconds_readout;
  char method[192];          /* how the extrinsics were found, one sentence (extrinsics.yaml's method) */
} planarvo_camera_calibration_result;

PLANARVO_API void planarvo_camera_calibration_options_init(planarvo_camera_calibration_options* options);
/* Calibrates from a data set (its frames, odometry.txt or the odometry topic for the odometry
 * method; direction.txt for the nonholonomic one, or, without labels, the odometry's sign: +1 / -1
 * by its forward motion, 0 when slower than the graph's still_speed, and the result's method says
 * so). PLANARVO_ERROR_INVALID_INPUT when the method's inputs are missing;
 * PLANARVO_ERROR_FAILED (the reason as the message) when the status is not OK, the result filled
 * in either case. */
PLANARVO_API planarvo_status planarvo_calibrate_dataset(planarvo_context* context, planarvo_dataset* dataset,
                                                        const planarvo_camera_calibration_options* options,
                                                        planarvo_camera_calibration_result* result);

/* The same calibration on a stream of frames (a camera, a bag): frames are fed one at a time with
 * the robot's wheel-odometry pose at the frame's time (NULL when there is none) and the direction
 * label of the interval ending at the frame (NULL when there is none); the frames that roll and
 * pitch use are held until those are known, then tracked. */
typedef struct planarvo_camera_calibrator planarvo_camera_calibrator;
/* camera: the distorted camera the frames come from. options may be NULL. */
PLANARVO_API planarvo_status planarvo_camera_calibrator_create(planarvo_context* context,
                                                               const planarvo_camera* camera,
                                                               const planarvo_camera_calibration_options* options,
                                                               planarvo_camera_calibrator** calibrator);
PLANARVO_API void planarvo_camera_calibrator_destroy(planarvo_camera_calibrator* calibrator);
/* odometry_pose NULL: the pose interpolated at the frame's time from the samples given by then
 * with planarvo_camera_calibrator_add_odometry (none when they do not reach it). */
PLANARVO_API planarvo_status planarvo_camera_calibrator_add_frame(planarvo_camera_calibrator* calibrator,
                                                                  const planarvo_image* image, double timestamp,
                                                                  const planarvo_se2* odometry_pose,
                                                                  const int32_t* direction);
/* A wheel-odometry sample (the robot's pose at `timestamp`), in time order: the calibrator
 * interpolates the frames' poses from them (linear in x, y and the angle the shorter way round), so
 * a stream's odometry messages can be given as they come, before or after the frames they cover.
 * PLANARVO_ERROR_INVALID_ARGUMENT for a sample not after the one before or not finite. */
PLANARVO_API planarvo_status planarvo_camera_calibrator_add_odometry(planarvo_camera_calibrator* calibrator,
                                                                     double timestamp, const planarvo_se2* pose);
/* Runs what is left and fills result (once per calibrator); PLANARVO_ERROR_FAILED with the reason
 * when the status is not OK, the result filled in either case. */
PLANARVO_API planarvo_status planarvo_camera_calibrator_finish(planarvo_camera_calibrator* calibrator,
                                                               planarvo_camera_calibration_result* result);

/* Writes the calibration's extrinsics as extrinsics.yaml (docs/formats.md): the values, the 6x6
 * covariance, the parameters it estimated, its method sentence, and notes: `notes` (where the
 * data came from; NULL: none) and, when the rolling shutter's readout time was estimated, the
 * estimate. PLANARVO_ERROR_IO when the file cannot be written. */
PLANARVO_API planarvo_status planarvo_camera_calibration_save(const char* path,
                                                              const planarvo_camera_calibration_result* result,
                                                              const char* notes);

/* The stages on their own. Motions from a data set: tracks every frame with the given extrinsics
 * (the camera's roll and pitch matter; the graph calibration tracks with x = y = 0, z = 1, yaw = 0)
 * and writes one motion pair per tracked interval (lost ones left out): as the sensor's, the
 * camera's own motion (planarvo_sensor_motion of the tracked robot motion and its covariance,
 * which is the tracked motion itself at x = y = 0, z = 1, yaw = 0), so that the pairs calibrate
 * correctly whatever extrinsics tracked them, as track --motions-out writes them; the data set's
 * odometry and direction label where it has them.
 * capacity must be at least the frame count - 1; *count receives the pairs written (each with
 * struct_size = sizeof(planarvo_motion_pair)). options may be NULL. */
PLANARVO_API planarvo_status planarvo_track_motions(planarvo_context* context, planarvo_dataset* dataset,
                                                    const planarvo_extrinsics* extrinsics,
                                                    const planarvo_tracker_options* options,
                                                    planarvo_motion_pair* pairs, size_t capacity, size_t* count);
/* Composition: roll and pitch (with their 2x2 covariance, row-major; NULL when they were given,
 * not estimated) and a graph calibration's x, y, scale (the height) and yaw as the camera's
 * extrinsics, their 6x6 covariance (order x y z roll pitch yaw, row-major; zero rows for what was
 * not estimated) and, per parameter, whether it was estimated (any output may be NULL). The two
 * stages are taken as independent here; the whole calibration (planarvo_calibrate_dataset, the
 * calibrator) also carries the tilt's error into x, y, z and yaw, which motion pairs cannot. */
PLANARVO_API planarvo_status planarvo_compose_extrinsics(double roll, double pitch,
                                                         const double* roll_pitch_covariance,
                                                         const planarvo_calibration_result* graph,
                                                         planarvo_extrinsics* extrinsics, double* covariance,
                                                         int32_t* estimated);

#endif /* PLANARVO_CALIBRATION_H */
