/*
 * planarvo: the floor mosaic. Part of planarvo/planarvo.h, which includes it where the types it
 * uses are defined: include <planarvo/planarvo.h>, not this file.
 */
#ifndef PLANARVO_MOSAIC_H
#define PLANARVO_MOSAIC_H

#ifndef PLANARVO_INSIDE_PLANARVO_H
#error "include <planarvo/planarvo.h>, not <planarvo/mosaic.h>"
#endif

/* ------------------------------------------------------------------------------------------ */
/* The floor mosaic (docs/formats.md, "Mosaic")                                               */

/* An image of the ground under a trajectory: each frame used is warped onto the ground plane
 * through its homography on the device, corrected by a gain estimated against the mosaic built so
 * far, and blended with feathering weights. The grid is placed as ROS map_server places a map:
 * pixel (col, row) covers x in origin_x + [col, col + 1) * resolution and y in
 * origin_y + [height - 1 - row, height - row) * resolution, in the trajectory's frame. Unseen pixels
 * are 0, seen ones 1..255. Memory: float accumulators only for the tiles in view at once, plus the
 * 8-bit image. Thread safety: one thread at a time. */
typedef struct planarvo_mosaic planarvo_mosaic;

typedef struct planarvo_mosaic_options {
  size_t struct_size;
  double resolution;      /* metres per mosaic pixel; default 0.001 */
  double max_range;       /* ground farther than this from the camera's foot point is not used,
                             metres; default 0: 4 x the camera height */
  double frame_spacing;   /* a frame is used once the camera's foot point has moved this far
                             (metres) or the robot has turned 5 degrees since the last frame used;
                             default 0: an eighth of the shorter side of the ground in view;
                             negative: every frame */
  int32_t estimate_gain;  /* non-zero: a gain per frame against the mosaic so far; default 1 */
  int32_t max_side;       /* a larger mosaic is PLANARVO_ERROR_INVALID_INPUT naming its size;
                             default 20000 */
  planarvo_progress_fn progress;
  void* progress_user_data;
  /* Extrinsics outside the plausible ranges of a camera on a vehicle (|x|, |y| <= 20 m, 0 < z <=
   * 5 m, angles within 2 pi; millimetres or degrees by mistake) are PLANARVO_ERROR_INVALID_ARGUMENT
   * naming the likely mistake unless this is non-zero; default 0. Read only when struct_size
   * covers it. */
  int32_t accept_unusual_extrinsics;
} planarvo_mosaic_options;

typedef struct planarvo_mosaic_info {
  size_t struct_size;
  int32_t width, height;
  double resolution;          /* metres per pixel */
  double origin_x, origin_y;  /* the lower-left corner of the lower-left pixel, metres */
  int64_t frames_given, frames_used;
  int64_t covered_pixels;     /* pixels some frame saw (value 1..255) */
  double gain_min, gain_max;  /* of the per-frame gains */
  int64_t peak_tile_bytes;    /* float accumulators held at once */
  double seconds_decode, seconds_warp, seconds_blend, seconds_total;
} planarvo_mosaic_info;

PLANARVO_API void planarvo_mosaic_options_init(planarvo_mosaic_options* options);
/* Builds the mosaic of a data set's frames at the robot's poses: timestamps[i] (the data set's
 * times, seconds after its first frame's stamp for a bag) and poses[i], i < count, in increasing
 * time; each time must be a frame's (within 1 ms, or a quarter of the shortest frame interval),
 * else PLANARVO_ERROR_INVALID_INPUT naming the first that is not; a trajectory may leave frames
 * out. extrinsics: the camera on the robot, in the units of the poses. options may be NULL.
 * PLANARVO_ERROR_INVALID_INPUT also for count 0 and a mosaic over max_side pixels on a side.
 * A rolling-shutter camera (the data set's readout: its camera file's, or
 * planarvo_dataset_set_readout's) is warped row by row, each row from the robot's pose when it was
 * read: the motion between two poses held constant (an arc), the last interval's after the last. */
PLANARVO_API planarvo_status planarvo_mosaic_build(planarvo_context* context, planarvo_dataset* dataset,
                                                   const planarvo_extrinsics* extrinsics,
                                                   const double* timestamps, const planarvo_se2* poses,
                                                   size_t count, const planarvo_mosaic_options* options,
                                                   planarvo_mosaic** mosaic);
PLANARVO_API void planarvo_mosaic_destroy(planarvo_mosaic* mosaic);
PLANARVO_API planarvo_status planarvo_mosaic_info_get(const planarvo_mosaic* mosaic, planarvo_mosaic_info* info);
/* The 8-bit image; *image points into memory owned by the mosaic, valid until it is destroyed. */
PLANARVO_API planarvo_status planarvo_mosaic_image(const planarvo_mosaic* mosaic, planarvo_image* image);
/* Writes the image to image_path (PNG for .png; any format OpenCV writes by extension) and the
 * map_server YAML beside it with the same stem and .yaml (image, resolution, origin [x, y, yaw],
 * mode trinary, negate 0, occupied_thresh 1.0, free_thresh 0.998: map_server and nav2's load every
 * seen pixel as free and every unseen one as unknown; docs/formats.md). */
PLANARVO_API planarvo_status planarvo_mosaic_save(const planarvo_mosaic* mosaic, const char* image_path);
/* Writes a contrast-stretched copy of the image for an ordinary viewer (the seen pixels' 1st to
 * 99th percentile of grey over 1..255; unseen stays 0) to path, format by extension. */
PLANARVO_API planarvo_status planarvo_mosaic_save_preview(const planarvo_mosaic* mosaic, const char* path);

#endif /* PLANARVO_MOSAIC_H */
