// The pixels the tracker aligns when it subsamples a level: one per B x B block of a keyframe's
// level at a hashed offset, a jittered grid (kernels/track/select_pixels.cl documents the rule, why
// not by gradient, and the output). Gathered once per keyframe on the device into a compact
// grid; the fused pass built with SELECT = 1 and select_block = B (WarpReduceOptions::select_block) then visits
// only them, so a full-resolution pass costs about what a pass over 1 / B^2 of the pixels costs
// (src/track/README.md, "Full resolution from subsampled pixels").
#pragma once
#include <cstdint>
#include <vector>

#include <CL/opencl.hpp>

#include "image/pyramid.h"
#include "track/warp_reduce.h"

namespace planarvo::ocl {
class Runtime;
}

namespace planarvo::track {

// A level's selected pixels on the device: grid_w x grid_h float4 entries (select_pixels.cl).
struct SelectedPixels {
  int level = -1;  // the pyramid level they were chosen from; -1: none
  int block = 0;
  int grid_w = 0, grid_h = 0;
  cl::Buffer data;
};

inline int selection_grid_size(int level_size, int block) { return (level_size + block - 1) / block; }

class PixelSelector {
 public:
  explicit PixelSelector(ocl::Runtime& runtime);
  // Gathers the pixels of `level` (pyramid level number `level_index`) into *out, reusing its
  // buffer when it is large enough. block 1..64.
  void run(const PyramidLevel& level, int level_index, int block, SelectedPixels* out);

 private:
  ocl::Runtime& runtime_;
  cl::Kernel kernel_;
};

// The offset within block (bx, by) of its pixel, 0 .. block^2 - 1 (the kernel's sp_hash).
uint32_t select_offset(int bx, int by, int block);
// The plain C++ reference: the same rule on a host level; returns grid_w * grid_h * 4 floats.
std::vector<float> select_pixels_reference(const LevelView& level, int block);

}  // namespace planarvo::track
