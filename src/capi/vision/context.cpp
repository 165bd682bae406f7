// C API: OpenCL device listing and the context (a planarvo::ocl::Runtime).
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "capi/convert.h"
#include "capi/handles.h"
#include "capi/status.h"
#include "core/error.h"
#include "ocl/cache_dirs.h"
#include "ocl/runtime.h"

using planarvo::capi::guard;
using planarvo::capi::require;

namespace {

void fill_info(const planarvo::ocl::DeviceInfo& d, planarvo_device_info* out) {
  const size_t struct_size = out->struct_size;
  planarvo_device_info info;
  std::memset(&info, 0, sizeof info);
  info.struct_size = struct_size;
  info.index = d.global_index;
  planarvo::capi::copy_string(info.platform_name, sizeof info.platform_name, d.platform_name);
  planarvo::capi::copy_string(info.device_name, sizeof info.device_name, d.device_name);
  planarvo::capi::copy_string(info.device_type, sizeof info.device_type, d.type);
  planarvo::capi::copy_string(info.device_version, sizeof info.device_version, d.device_version);
  planarvo::capi::copy_string(info.opencl_c_version, sizeof info.opencl_c_version, d.opencl_c_version);
  planarvo::capi::copy_string(info.driver_version, sizeof info.driver_version, d.driver_version);
  info.image_support = d.image_support;
  info.fp64 = d.fp64;
  info.local_mem_size = d.local_mem_size;
  info.global_mem_size = d.global_mem_size;
  info.max_work_group_size = d.max_work_group_size;
  info.compute_units = d.compute_units;
  info.driver_caches_kernels = planarvo::ocl::detail::driver_caches_kernels(d.platform_name) ? 1 : 0;
  // Copy only as much as the caller's struct holds (an older, shorter struct stays valid).
  std::memcpy(out, &info, std::min(struct_size, sizeof info));
}

// "track,calibrate" as names; "" or NULL: none (every kernel). An empty name is InvalidArgument.
std::vector<std::string> use_names(const char* uses, const char* fn) {
  std::vector<std::string> names;
  for (const char* p = uses ? uses : ""; *p;) {
    const char* end = std::strchr(p, ',');
    if (!end) end = p + std::strlen(p);
    std::string name(p, end);
    name.erase(0, name.find_first_not_of(' '));
    name.erase(name.find_last_not_of(' ') + 1);
    if (name.empty()) planarvo::throw_invalid_argument(std::string(fn) + ": an empty name in uses \"" + uses + "\"");
    names.push_back(name);
    p = *end ? end + 1 : end;
  }
  return names;
}

}  // namespace

extern "C" {

PLANARVO_API planarvo_status planarvo_list_devices(planarvo_device_info* devices, size_t capacity,
                                                   size_t* count) {
  return guard([&] {
    require(count != nullptr, "planarvo_list_devices: count is NULL");
    const auto all = planarvo::ocl::list_devices();
    *count = all.size();
    if (!devices) return;
    if (capacity < all.size())
      throw planarvo::capi::BufferTooSmall("planarvo_list_devices: " + std::to_string(all.size()) +
                                           " devices, capacity " + std::to_string(capacity));
    for (size_t i = 0; i < all.size(); ++i) {
      planarvo::capi::require_struct_size(devices[i].struct_size,
                                          offsetof(planarvo_device_info, compute_units) + 4,
                                          "planarvo_device_info");
      fill_info(all[i], &devices[i]);
    }
  });
}

PLANARVO_API void planarvo_context_options_init(planarvo_context_options* options) {
  if (!options) return;
  std::memset(options, 0, sizeof *options);
  options->struct_size = sizeof *options;
}

PLANARVO_API planarvo_status planarvo_context_create(const planarvo_context_options* options,
                                                     planarvo_context** context) {
  return guard([&] {
    require(context != nullptr, "planarvo_context_create: context is NULL");
    *context = nullptr;
    planarvo::ocl::RuntimeOptions ro;
    if (options) {
      planarvo::capi::require_struct_size(
          options->struct_size, offsetof(planarvo_context_options, kernel_binaries_dir) + sizeof(char*),
          "planarvo_context_options");
      if (options->device) ro.device = options->device;
      if (options->cache_dir) ro.cache_dir = options->cache_dir;
      ro.use_cache = options->disable_cache == 0;
      if (options->kernel_binaries_dir) ro.binaries_dir = options->kernel_binaries_dir;
    }
    auto ctx = std::make_unique<planarvo_context>();
    ctx->runtime = std::make_unique<planarvo::ocl::Runtime>(ro);
    *context = ctx.release();
  });
}

PLANARVO_API void planarvo_context_destroy(planarvo_context* context) { delete context; }

PLANARVO_API planarvo_status planarvo_context_device(const planarvo_context* context,
                                                     planarvo_device_info* info) {
  return guard([&] {
    require(context != nullptr, "planarvo_context_device: context is NULL");
    require(info != nullptr, "planarvo_context_device: info is NULL");
    planarvo::capi::require_struct_size(info->struct_size,
                                        offsetof(planarvo_device_info, compute_units) + 4,
                                        "planarvo_device_info");
    fill_info(context->runtime->device_info(), info);
  });
}

PLANARVO_API const char* planarvo_context_cache_dir(const planarvo_context* context) {
  return context ? context->runtime->cache_dir().c_str() : "";
}

PLANARVO_API planarvo_status planarvo_context_export_kernels(planarvo_context* context,
                                                             const char* dir) {
  return guard([&] {
    require(context != nullptr, "planarvo_context_export_kernels: context is NULL");
    require(dir != nullptr && *dir, "planarvo_context_export_kernels: dir is NULL or empty");
    context->runtime->export_binaries(dir);
  });
}

PLANARVO_API planarvo_status planarvo_context_export_kernels_for(planarvo_context* context,
                                                                 const char* dir, const char* uses,
                                                                 size_t* exported) {
  return guard([&] {
    require(context != nullptr, "planarvo_context_export_kernels_for: context is NULL");
    require(dir != nullptr && *dir, "planarvo_context_export_kernels_for: dir is NULL or empty");
    const std::vector<std::string> names = use_names(uses, "planarvo_context_export_kernels_for");
    const size_t n = context->runtime->export_binaries(dir, names);
    if (exported) *exported = n;
  });
}

PLANARVO_API planarvo_status planarvo_context_prepare_kernels(planarvo_context* context) {
  return guard([&] {
    require(context != nullptr, "planarvo_context_prepare_kernels: context is NULL");
    context->runtime->prepare_all();
  });
}

PLANARVO_API planarvo_status planarvo_context_prepare_kernels_for(planarvo_context* context, const char* uses) {
  return guard([&] {
    require(context != nullptr, "planarvo_context_prepare_kernels_for: context is NULL");
    context->runtime->prepare(use_names(uses, "planarvo_context_prepare_kernels_for"));
  });
}

}  // extern "C"
