// SHA-256 (FIPS 180-4) of a byte string, as 64 lowercase hex digits: what the kernel-binaries
// manifest records of each binary, so that a truncated, swapped or corrupted file is refused
// before an OpenCL driver parses it (src/ocl/manifest.h).
#pragma once
#include <cstddef>
#include <string>

namespace planarvo {

std::string sha256_hex(const void* data, size_t size);

}  // namespace planarvo
