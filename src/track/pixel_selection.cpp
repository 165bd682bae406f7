#include "track/pixel_selection.h"

#include "core/error.h"
#include "core/tasks.h"
#include "ocl/runtime.h"

namespace planarvo::track {

namespace {

// The program has no build options; registered for export with the tracker's uses (the
// calibration's tracking stage subsamples too: the tracker's default levels).
const bool kRegistered = [] {
  ocl::Runtime::register_build_options("select_pixels", "", {tasks::kTrack, tasks::kCalibrate});
  return true;
}();

}  // namespace

PixelSelector::PixelSelector(ocl::Runtime& runtime)
    : runtime_(runtime), kernel_(runtime.program("select_pixels", ""), "select_pixels") {}

uint32_t select_offset(int bx, int by, int block) {
  const uint32_t ubx = static_cast<uint32_t>(bx), uby = static_cast<uint32_t>(by);
  uint32_t h = (ubx * 0x9E3779B1u) ^ ((uby + 0x7F4A7C15u) * 0x85EBCA77u);
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  // select_pixels.cl: the low 16 bits scaled to the column, the high 16 to the row.
  const uint32_t b = static_cast<uint32_t>(block);
  const uint32_t ox = ((h & 0xFFFFu) * b) >> 16, oy = ((h >> 16) * b) >> 16;
  return oy * b + ox;
}

void PixelSelector::run(const PyramidLevel& level, int level_index, int block, SelectedPixels* out) {
  if (block < 1 || block > 64) throw_invalid_argument("PixelSelector::run: block must be 1..64");
  if (level.width < 1 || level.height < 1) throw_invalid_argument("PixelSelector::run: empty level");
  const int gw = selection_grid_size(level.width, block), gh = selection_grid_size(level.height, block);
  const size_t bytes = static_cast<size_t>(gw) * static_cast<size_t>(gh) * 4 * sizeof(float);
  if (!out->data() || static_cast<size_t>(out->grid_w) * static_cast<size_t>(out->grid_h) * 4 * sizeof(float) < bytes)
    out->data = cl::Buffer(runtime_.context(), CL_MEM_READ_WRITE, bytes);
  out->level = level_index;
  out->block = block;
  out->grid_w = gw;
  out->grid_h = gh;
  int a = 0;
  kernel_.setArg(a++, level.data);
  kernel_.setArg(a++, level.width);
  kernel_.setArg(a++, level.height);
  kernel_.setArg(a++, block);
  kernel_.setArg(a++, out->data);
  kernel_.setArg(a++, gw);
  kernel_.setArg(a++, gh);
  constexpr size_t kWg = 8;
  const auto up = [](int n) { return (static_cast<size_t>(n) + kWg - 1) / kWg * kWg; };
  runtime_.queue().enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(up(gw), up(gh)), cl::NDRange(kWg, kWg));
}

std::vector<float> select_pixels_reference(const LevelView& level, int block) {
  if (block < 1 || block > 64) throw_invalid_argument("select_pixels_reference: block must be 1..64");
  const int gw = selection_grid_size(level.width, block), gh = selection_grid_size(level.height, block);
  std::vector<float> grid(static_cast<size_t>(gw) * static_cast<size_t>(gh) * 4, 0.0f);
  for (int by = 0; by < gh; ++by)
    for (int bx = 0; bx < gw; ++bx) {
      const int off = static_cast<int>(select_offset(bx, by, block));
      const int x = bx * block + off % block, y = by * block + off / block;
      if (x >= level.width || y >= level.height) continue;
      const float* p = level.data + 4 * (static_cast<size_t>(y) * static_cast<size_t>(level.stride) + static_cast<size_t>(x));
      if (p[3] == 0.0f) continue;
      float* g = &grid[4 * (static_cast<size_t>(by) * static_cast<size_t>(gw) + static_cast<size_t>(bx))];
      g[0] = p[0];
      g[1] = p[1];
      g[2] = p[2];
      g[3] = static_cast<float>(1 + off % block + 256 * (off / block));  // select_pixels.cl's code
    }
  return grid;
}

}  // namespace planarvo::track
