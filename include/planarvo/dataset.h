/*
 * planarvo: data sets, ROS bags and the files a run writes. Part of planarvo/planarvo.h, which
 * includes it where the types it uses are defined: include <planarvo/planarvo.h>, not this file.
 */
#ifndef PLANARVO_DATASET_H
#define PLANARVO_DATASET_H

#ifndef PLANARVO_INSIDE_PLANARVO_H
#error "include <planarvo/planarvo.h>, not <planarvo/dataset.h>"
#endif

/* ------------------------------------------------------------------------------------------ */
/* Data sets (docs/formats.md)                                                                 */

/* A data set directory (camera.yaml, frames.txt + images/, or a video; optional odometry.txt,
 * direction.txt, groundtruth.txt, extrinsics.yaml, extrinsics_gt.yaml), or a recorded log: a ROS 1
 * bag (format 2.0) or a ROS 2 MCAP file, recognised by its first bytes, whatever its name, or the
 * directory `ros2 bag record` writes (metadata.yaml and one .mcap file). Read and
 * validated on open; images are decoded on demand by planarvo_dataset_frame. A bag's frames are
 * the messages of one image topic; its camera comes from a CameraInfo topic or a camera.yaml; its
 * odometry and ground truth from nav_msgs/Odometry topics (docs/formats.md, "ROS bags"). Times
 * are seconds since the first frame's stamp (planarvo_dataset_info.time_origin_ns), taken
 * relative in integer nanoseconds so that no precision is lost. Thread safety: one thread at a
 * time. */
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
  /* Non-zero: an image that frames.txt lists but that does not exist is not an error at open
   * (it is by default, found by one file-system check per image); reading its frame fails with
   * PLANARVO_ERROR_INVALID_INPUT, like an undecodable image, for callers that skip bad frames
   * (planarvo track --skip-bad-frames). Ignored with verify_images. */
  int32_t allow_missing_images;
  /* Bags only (NULL or "": none, except image_topic). image_topic: the frames
   * (sensor_msgs/Image mono8, bgr8, rgb8, bgra8, rgba8, bayer_*8, or CompressedImage); NULL: the
   * bag's only image topic. camera_info_topic (sensor_msgs/CameraInfo, plumb_bob or no
   * distortion) or camera_yaml (OpenCV calibration YAML): the camera; exactly one of them.
   * odometry_topic, groundtruth_topic: nav_msgs/Odometry; odometry_topic NULL: the bag's only
   * Odometry topic other than groundtruth_topic, none when it has several. */
  const char* image_topic;
  const char* camera_info_topic;
  const char* camera_yaml;
  const char* odometry_topic;
  const char* groundtruth_topic;
  /* Non-zero: time messages by when the recorder received them (the bag's record time) instead
   * of their header stamps. */
  int32_t use_receive_time;
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
  /* A bag's first frame's stamp, integer nanoseconds since the Unix epoch; the data set's times
   * are seconds after it. 0 for a data set directory, whose times are as frames.txt gives them. */
  int64_t time_origin_ns;
  int32_t is_bag;
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
/* Replaces the data set camera's region of interest (camera.yaml's region_of_interest) for
 * everything that reads the data set from now on (planarvo_dataset_info_get, the calibration);
 * roi NULL or all zero: the whole image. PLANARVO_ERROR_INVALID_INPUT, changing nothing, when it
 * does not lie inside the image or is smaller than 16 pixels on a side. */
PLANARVO_API planarvo_status planarvo_dataset_set_roi(planarvo_dataset* dataset, const planarvo_region* roi);
/* Replaces the data set camera's rolling-shutter readout (camera.yaml's rolling_shutter_readout:
 * seconds from the first row's read to the last's; 0 = a global shutter) for everything that reads
 * the data set from now on. source names where the value came from in the error message (NULL:
 * "the readout time"). PLANARVO_ERROR_INVALID_INPUT, changing nothing, when it is negative, not
 * finite or longer than the frames' median interval. */
PLANARVO_API planarvo_status planarvo_dataset_set_readout(planarvo_dataset* dataset, double seconds,
                                                          const char* source);
PLANARVO_API planarvo_status planarvo_dataset_frame_data(const planarvo_dataset* dataset,
                                                         int64_t index, planarvo_frame_data* data);
/* Decodes frame index as 8-bit grey. *image points into memory owned by the data set, valid until
 * the next call on it or its destruction. */
PLANARVO_API planarvo_status planarvo_dataset_frame(planarvo_dataset* dataset, int64_t index,
                                                    planarvo_image* image);

/* The topics of a ROS 1 bag or MCAP file, one per line: "name<TAB>type<TAB>count\n" (count -1
 * when the file does not say), in the file's order, as a NUL-terminated string in buffer (size
 * bytes; NULL with size 0 to ask). *needed, when not NULL, receives the bytes the whole list takes
 * with its NUL; PLANARVO_ERROR_INVALID_ARGUMENT, writing nothing, when size is less. */
PLANARVO_API planarvo_status planarvo_bag_topics(const char* path, char* buffer, size_t size, size_t* needed);

/* Reads a TUM trajectory (t x y z qx qy qz qw per line, '#' comments; planar poses only: z, qx
 * and qy zero to 1e-6, else PLANARVO_ERROR_INVALID_INPUT naming the line), times increasing.
 * Writes at most capacity entries; *count receives the number in the file (call with capacity 0
 * and NULL arrays to ask); PLANARVO_ERROR_INVALID_ARGUMENT, writing nothing, when capacity is
 * less but not 0. */
PLANARVO_API planarvo_status planarvo_read_tum(const char* path, double* timestamps, planarvo_se2* poses,
                                               size_t capacity, size_t* count);

/* One frame's body attitude relative to the local ground plane (radians), as plane.txt holds it
 * (planarvo track --plane-out, docs/formats.md). */
typedef struct planarvo_plane_attitude {
  double timestamp;
  double roll, pitch;
  double sigma_roll, sigma_pitch;
} planarvo_plane_attitude;
/* Writes plane.txt ("t roll pitch sigma_roll sigma_pitch" per line), complete or not at all.
 * PLANARVO_ERROR_INVALID_ARGUMENT for timestamps that do not increase, non-finite values or a
 * negative sigma; PLANARVO_ERROR_IO when it cannot be written. */
PLANARVO_API planarvo_status planarvo_write_plane(const char* path, const planarvo_plane_attitude* rows, size_t count);

/* Reads plane.txt (t roll pitch sigma_roll sigma_pitch per line, '#' comments; times increasing,
 * |roll| and |pitch| at most pi/2, sigmas not negative, else PLANARVO_ERROR_INVALID_INPUT naming
 * the line). capacity and count as planarvo_read_tum. */
PLANARVO_API planarvo_status planarvo_read_plane(const char* path, planarvo_plane_attitude* rows, size_t capacity,
                                                 size_t* count);

/* Writes a TUM trajectory (t x y z qx qy qz qw, z = 0, rotation about z). */
PLANARVO_API planarvo_status planarvo_write_tum(const char* path, const double* timestamps,
                                                const planarvo_se2* poses, size_t count);

/* Per-frame statistics CSV (timestamp, vx, vy, omega, iterations, final_cost, inlier_fraction,
 * ms, status, roll, pitch, sigma_roll, sigma_pitch, mounting_changed; the last five empty unless
 * has_attitude): the header on open, then one row per call, flushed. Written as PATH.partial and
 * renamed onto PATH by planarvo_stats_writer_close, so PATH is complete or untouched:
 * planarvo_stats_writer_discard (after an error, say) removes the partial file and leaves an
 * existing PATH as it was; a crash leaves the rows written so far in PATH.partial. */
typedef struct planarvo_stats_writer planarvo_stats_writer;
typedef struct planarvo_frame_stats {
  double timestamp;
  double vx, vy, omega;  /* robot-frame velocity over the interval ending at this frame */
  int32_t iterations;    /* alignment steps, all levels */
  double final_cost, inlier_fraction;
  double ms;             /* engine time for the frame */
  const char* status;    /* "first", "ok", "degraded", "lost", ... */
  /* With the local plane (planarvo_track_result): non-zero has_attitude writes the body's attitude
   * (radians) with its standard deviations, and mounting_changed (0 or 1). */
  int32_t has_attitude;
  double roll, pitch, sigma_roll, sigma_pitch;
  int32_t mounting_changed;
} planarvo_frame_stats;
PLANARVO_API planarvo_status planarvo_stats_writer_open(const char* path, planarvo_stats_writer** writer);
PLANARVO_API planarvo_status planarvo_stats_writer_add(planarvo_stats_writer* writer,
                                                       const planarvo_frame_stats* row);
/* Completes the file (renames it onto PATH, reporting a failed write) and releases the writer;
 * NULL is allowed. */
PLANARVO_API planarvo_status planarvo_stats_writer_close(planarvo_stats_writer* writer);
/* Removes the partial file, leaves PATH as it was, and releases the writer; NULL is allowed. */
PLANARVO_API void planarvo_stats_writer_discard(planarvo_stats_writer* writer);

/* A statistics CSV read back, row by row. planarvo_stats_read takes the writer's header or its
 * first nine columns (files written before the local plane) and a row per frame, numbers as the
 * writer writes them (nan and inf included, but for the timestamp), status as written (RFC 4180
 * quoting); anything else, or no row, is PLANARVO_ERROR_INVALID_INPUT naming the file and line. */
typedef struct planarvo_stats_table planarvo_stats_table;
PLANARVO_API planarvo_status planarvo_stats_read(const char* path, planarvo_stats_table** table);
/* The number of rows; 0 for NULL. */
PLANARVO_API size_t planarvo_stats_table_size(const planarvo_stats_table* table);
/* Row `index` into *row; row->status points into the table, valid until it is freed.
 * PLANARVO_ERROR_INVALID_ARGUMENT for an index past the end. */
PLANARVO_API planarvo_status planarvo_stats_table_row(const planarvo_stats_table* table, size_t index,
                                                     planarvo_frame_stats* row);
/* Releases the table; NULL is allowed. */
PLANARVO_API void planarvo_stats_table_free(planarvo_stats_table* table);

#endif /* PLANARVO_DATASET_H */
