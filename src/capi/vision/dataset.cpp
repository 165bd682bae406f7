// C API: data sets (src/io/dataset/dataset.h).
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "capi/convert.h"
#include "capi/handles.h"
#include "capi/status.h"
#include "core/error.h"
#include "io/bag/bag.h"
#include "io/dataset/dataset.h"

using planarvo::capi::guard;
using planarvo::capi::require;

extern "C" {

PLANARVO_API void planarvo_dataset_options_init(planarvo_dataset_options* options) {
  if (!options) return;
  std::memset(options, 0, sizeof *options);
  options->struct_size = sizeof *options;
}

PLANARVO_API planarvo_status planarvo_dataset_open(const char* directory, const planarvo_dataset_options* options,
                                                   planarvo_dataset** dataset) {
  return guard([&] {
    require(dataset != nullptr, "planarvo_dataset_open: dataset is NULL");
    *dataset = nullptr;
    require(directory != nullptr && *directory, "planarvo_dataset_open: directory is NULL or empty");
    planarvo::io::DatasetOptions o;
    if (options) {
      planarvo::capi::require_struct_size(options->struct_size,
                                          offsetof(planarvo_dataset_options, progress_user_data) + sizeof(void*),
                                          "planarvo_dataset_options");
      if (options->video) o.video = options->video;
      o.verify_images = options->verify_images != 0;
      if (options->struct_size >= offsetof(planarvo_dataset_options, allow_missing_images) + sizeof(int32_t))
        o.allow_missing_images = options->allow_missing_images != 0 && !o.verify_images;
      if (options->struct_size >= offsetof(planarvo_dataset_options, use_receive_time) + sizeof(int32_t)) {
        planarvo::io::BagDatasetOptions& b = o.bag;
        for (auto [in, out] : {std::pair{options->image_topic, &b.image_topic},
                               std::pair{options->camera_info_topic, &b.camera_info_topic},
                               std::pair{options->camera_yaml, &b.camera_yaml},
                               std::pair{options->odometry_topic, &b.odometry_topic},
                               std::pair{options->groundtruth_topic, &b.groundtruth_topic}})
          if (in) *out = in;
        b.use_receive_time = options->use_receive_time != 0;
      }
      if (options->progress) {
        const planarvo_progress_fn fn = options->progress;
        void* user = options->progress_user_data;
        o.progress = [fn, user](double f, const char* stage) { return fn(user, f, stage) == 0; };
      }
    }
    auto handle = std::make_unique<planarvo_dataset>();
    handle->dataset = std::make_unique<planarvo::io::Dataset>(directory, o);
    *dataset = handle.release();
  });
}

PLANARVO_API planarvo_status planarvo_bag_topics(const char* path, char* buffer, size_t size, size_t* needed) {
  return guard([&] {
    require(path != nullptr && *path, "planarvo_bag_topics: path is NULL or empty");
    require(buffer != nullptr || size == 0, "planarvo_bag_topics: buffer is NULL with a size");
    const std::optional<std::string> file = planarvo::io::bag_file_for(path);
    const std::unique_ptr<planarvo::io::bag::BagFile> bag = planarvo::io::bag::open_bag(file ? *file : path);
    std::string list;
    for (const planarvo::io::bag::TopicInfo& t : bag->topics())
      list += t.name + "\t" + t.type + "\t" + std::to_string(t.count) + "\n";
    if (needed) *needed = list.size() + 1;
    if (size != 0 && size < list.size() + 1)
      planarvo::throw_invalid_argument("planarvo_bag_topics: the list takes " + std::to_string(list.size() + 1) +
                                       " bytes, the buffer has " + std::to_string(size));
    if (size) std::memcpy(buffer, list.c_str(), list.size() + 1);
  });
}

PLANARVO_API void planarvo_dataset_destroy(planarvo_dataset* dataset) { delete dataset; }

PLANARVO_API planarvo_status planarvo_dataset_set_roi(planarvo_dataset* dataset, const planarvo_region* roi) {
  return guard([&] {
    require(dataset != nullptr, "planarvo_dataset_set_roi: dataset is NULL");
    planarvo::PixelRegion r;
    if (roi) r = planarvo::PixelRegion{roi->x, roi->y, roi->width, roi->height};
    dataset->dataset->set_region_of_interest(r);
  });
}

PLANARVO_API planarvo_status planarvo_dataset_set_readout(planarvo_dataset* dataset, double seconds,
                                                          const char* source) {
  return guard([&] {
    require(dataset != nullptr, "planarvo_dataset_set_readout: dataset is NULL");
    dataset->dataset->set_rolling_shutter_readout(seconds, source ? source : "the readout time");
  });
}

PLANARVO_API planarvo_status planarvo_dataset_info_get(const planarvo_dataset* dataset, planarvo_dataset_info* info) {
  return guard([&] {
    require(dataset != nullptr && info != nullptr, "planarvo_dataset_info_get: NULL argument");
    planarvo::capi::require_struct_size(info->struct_size, offsetof(planarvo_dataset_info, time_origin_ns),
                                        "planarvo_dataset_info");
    const planarvo::io::Dataset& d = *dataset->dataset;
    planarvo_dataset_info out;
    std::memset(&out, 0, sizeof out);
    out.struct_size = info->struct_size;
    out.frame_count = d.frame_count();
    out.first_timestamp = d.timestamp(0);
    out.last_timestamp = d.timestamp(d.frame_count() - 1);
    out.camera = planarvo::capi::to_c(d.camera());
    out.has_odometry = d.has_odometry();
    out.has_direction = d.has_direction();
    out.has_groundtruth = d.has_groundtruth();
    if (d.extrinsics()) {
      out.has_extrinsics = 1;
      out.extrinsics = planarvo::capi::to_c(d.extrinsics()->value);
    }
    if (d.extrinsics_gt()) {
      out.has_extrinsics_gt = 1;
      out.extrinsics_gt = planarvo::capi::to_c(d.extrinsics_gt()->value);
    }
    out.time_origin_ns = d.time_origin_ns();
    out.is_bag = d.is_bag() ? 1 : 0;
    planarvo::capi::write_versioned(out, info);
  });
}

PLANARVO_API planarvo_status planarvo_dataset_frame_data(const planarvo_dataset* dataset, int64_t index,
                                                         planarvo_frame_data* data) {
  return guard([&] {
    require(dataset != nullptr && data != nullptr, "planarvo_dataset_frame_data: NULL argument");
    const planarvo::io::Dataset& d = *dataset->dataset;
    require(index >= 0 && index < d.frame_count(), "planarvo_dataset_frame_data: index out of range");
    planarvo_frame_data out;
    std::memset(&out, 0, sizeof out);
    out.timestamp = d.timestamp(index);
    if (auto o = d.odometry_at(index)) {
      out.has_odometry = 1;
      out.odometry = planarvo::capi::to_c(*o);
    }
    if (auto g = d.groundtruth_at(index)) {
      out.has_groundtruth = 1;
      out.groundtruth = planarvo::capi::to_c(*g);
    }
    if (auto s = d.direction_for_interval(index)) {
      out.has_direction = 1;
      out.direction = *s;
    }
    *data = out;
  });
}

PLANARVO_API planarvo_status planarvo_dataset_frame(planarvo_dataset* dataset, int64_t index, planarvo_image* image) {
  return guard([&] {
    require(dataset != nullptr && image != nullptr, "planarvo_dataset_frame: NULL argument");
    require(index >= 0 && index < dataset->dataset->frame_count(), "planarvo_dataset_frame: index out of range");
    dataset->frame = dataset->dataset->frame(index);
    image->data = dataset->frame.data;
    image->width = dataset->frame.cols;
    image->height = dataset->frame.rows;
    image->stride = dataset->frame.step[0];
    image->format = PLANARVO_GRAY8;
  });
}

}  // extern "C"
