// C API: the floor mosaic (src/mosaic/mosaic.h).
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "capi/convert.h"
#include "capi/handles.h"
#include "capi/status.h"
#include "core/error.h"
#include "mosaic/mosaic.h"

using planarvo::capi::guard;
using planarvo::capi::require;

struct planarvo_mosaic {
  planarvo::mosaic::Mosaic mosaic;
};

extern "C" {

PLANARVO_API void planarvo_mosaic_options_init(planarvo_mosaic_options* options) {
  if (!options) return;
  std::memset(options, 0, sizeof *options);
  options->struct_size = sizeof *options;
  const planarvo::mosaic::MosaicOptions d;
  options->resolution = d.resolution;
  options->max_range = d.max_range;
  options->frame_spacing = d.frame_spacing;
  options->estimate_gain = d.estimate_gain ? 1 : 0;
  options->max_side = d.max_side;
}

PLANARVO_API planarvo_status planarvo_mosaic_build(planarvo_context* context, planarvo_dataset* dataset,
                                                   const planarvo_extrinsics* extrinsics, const double* timestamps,
                                                   const planarvo_se2* poses, size_t count,
                                                   const planarvo_mosaic_options* options, planarvo_mosaic** mosaic) {
  return guard([&] {
    require(mosaic != nullptr, "planarvo_mosaic_build: mosaic is NULL");
    *mosaic = nullptr;
    require(context != nullptr && dataset != nullptr && extrinsics != nullptr,
            "planarvo_mosaic_build: context, dataset or extrinsics is NULL");
    require(count == 0 || (timestamps != nullptr && poses != nullptr), "planarvo_mosaic_build: NULL arrays");
    planarvo::mosaic::MosaicOptions o;
    if (options) {
      planarvo::capi::require_struct_size(options->struct_size,
                                          offsetof(planarvo_mosaic_options, progress_user_data) + sizeof(void*),
                                          "planarvo_mosaic_options");
      o.resolution = options->resolution;
      o.max_range = options->max_range;
      o.frame_spacing = options->frame_spacing;
      o.estimate_gain = options->estimate_gain != 0;
      o.max_side = options->max_side;
      if (options->struct_size >= offsetof(planarvo_mosaic_options, accept_unusual_extrinsics) + sizeof(int32_t))
        o.accept_unusual_extrinsics = options->accept_unusual_extrinsics != 0;
      if (options->progress) {
        const planarvo_progress_fn fn = options->progress;
        void* user = options->progress_user_data;
        o.progress = [fn, user](double f, const char* stage) { return fn(user, f, stage) == 0; };
      }
    }
    planarvo::io::Dataset& ds = *dataset->dataset;
    std::vector<double> frame_times(static_cast<size_t>(ds.frame_count()));
    for (size_t i = 0; i < frame_times.size(); ++i) frame_times[i] = ds.timestamp(static_cast<int64_t>(i));
    const std::vector<double> times(timestamps, timestamps + count);
    const std::vector<int64_t> index = planarvo::mosaic::match_frames(frame_times, times);
    std::vector<planarvo::mosaic::PosedFrame> frames(count);
    for (size_t i = 0; i < count; ++i) frames[i] = {index[i], planarvo::capi::to_cpp(poses[i])};
    auto handle = std::make_unique<planarvo_mosaic>();
    handle->mosaic = planarvo::mosaic::build_mosaic(*context->runtime, ds, planarvo::capi::to_cpp(*extrinsics),
                                                    frames, o);
    *mosaic = handle.release();
  });
}

PLANARVO_API void planarvo_mosaic_destroy(planarvo_mosaic* mosaic) { delete mosaic; }

PLANARVO_API planarvo_status planarvo_mosaic_info_get(const planarvo_mosaic* mosaic, planarvo_mosaic_info* info) {
  return guard([&] {
    require(mosaic != nullptr && info != nullptr, "planarvo_mosaic_info_get: NULL argument");
    planarvo::capi::require_struct_size(info->struct_size, sizeof(planarvo_mosaic_info), "planarvo_mosaic_info");
    const planarvo::mosaic::Mosaic& m = mosaic->mosaic;
    const planarvo::mosaic::MosaicStats& s = m.stats;
    info->width = m.grid.width;
    info->height = m.grid.height;
    info->resolution = m.grid.resolution;
    info->origin_x = m.grid.origin.x();
    info->origin_y = m.grid.origin.y();
    info->frames_given = s.frames_given;
    info->frames_used = s.frames_used;
    info->covered_pixels = s.covered_pixels;
    info->gain_min = s.gain_min;
    info->gain_max = s.gain_max;
    info->peak_tile_bytes = s.peak_tile_bytes;
    info->seconds_decode = s.seconds_decode;
    info->seconds_warp = s.seconds_warp;
    info->seconds_blend = s.seconds_blend;
    info->seconds_total = s.seconds_total;
  });
}

PLANARVO_API planarvo_status planarvo_mosaic_image(const planarvo_mosaic* mosaic, planarvo_image* image) {
  return guard([&] {
    require(mosaic != nullptr && image != nullptr, "planarvo_mosaic_image: NULL argument");
    const cv::Mat& m = mosaic->mosaic.image;
    image->data = m.data;
    image->width = m.cols;
    image->height = m.rows;
    image->stride = m.step[0];
    image->format = PLANARVO_GRAY8;
  });
}

PLANARVO_API planarvo_status planarvo_mosaic_save(const planarvo_mosaic* mosaic, const char* image_path) {
  return guard([&] {
    require(mosaic != nullptr, "planarvo_mosaic_save: mosaic is NULL");
    require(image_path != nullptr && *image_path, "planarvo_mosaic_save: image_path is NULL or empty");
    planarvo::mosaic::save_mosaic(mosaic->mosaic, image_path);
  });
}

PLANARVO_API planarvo_status planarvo_mosaic_save_preview(const planarvo_mosaic* mosaic, const char* path) {
  return guard([&] {
    require(mosaic != nullptr, "planarvo_mosaic_save_preview: mosaic is NULL");
    require(path != nullptr && *path, "planarvo_mosaic_save_preview: path is NULL or empty");
    planarvo::mosaic::save_preview(mosaic->mosaic, path);
  });
}

}  // extern "C"
