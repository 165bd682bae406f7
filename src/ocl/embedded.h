// Kernel sources embedded at build time from kernels/<layer>/*.cl (cmake/EmbedKernels.cmake).
#pragma once
#include <cstddef>

namespace planarvo::ocl {

struct EmbeddedSource {
  const char* name;  // the file's stem: kernels/sim/render.cl -> "render"
  const char* source;
  size_t size;
};

// Terminated by an entry whose name is nullptr.
const EmbeddedSource* embedded_sources();

}  // namespace planarvo::ocl
