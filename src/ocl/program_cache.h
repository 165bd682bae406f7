// The on-disk program cache's file format and the file helpers that the cache and the binaries
// export share. Internal to src/ocl.
//
// A cache entry is one file, <cache_dir>/<program>-<32 hex digits>.clbin, where the hex digits
// are two 64-bit hashes of the entry's key string (see cache_key()). Layout, integers little-
// endian:
//   8 bytes  magic "PVCLPROG"
//   u32      format version (kCacheFormatVersion)
//   u32      key length K
//   K bytes  the full key string (so a file-name collision or a stale entry is detected)
//   u64      binary size N
//   u64      FNV-1a 64 of the binary (so overwritten bytes are detected before the driver
//            sees them: some drivers crash on a corrupt binary instead of rejecting it)
//   N bytes  the device binary (CL_PROGRAM_BINARIES)
// The file must end exactly there. Anything else is a miss.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ocl/runtime.h"

namespace planarvo::ocl::detail {

inline constexpr uint32_t kCacheFormatVersion = 1;

// The program cache directory that options select ("" when caching is off).
std::string resolve_cache_dir(const RuntimeOptions& options);

// The canonical key string of a program built from source with effective_options on device.
std::string cache_key(const std::string& name, const std::string& source,
                      const std::string& effective_options, const DeviceInfo& device);

// <cache_dir>/<name>-<hash of key>.clbin
std::filesystem::path cache_entry_path(const std::string& cache_dir, const std::string& name,
                                       const std::string& key);

std::vector<unsigned char> encode_cache_entry(const std::string& key,
                                              const std::vector<unsigned char>& binary);
// The binary, when bytes are a well-formed entry for exactly this key; nullopt otherwise.
std::optional<std::vector<unsigned char>> decode_cache_entry(
    const std::vector<unsigned char>& bytes, const std::string& key);

// The whole file; nullopt when it cannot be opened or read.
std::optional<std::vector<unsigned char>> read_file(const std::filesystem::path& path);
// Writes to a temporary file beside path and renames it over path, so that a reader never sees
// a half-written file. Returns false (and leaves no temporary behind) on any failure.
bool write_file_atomically(const std::filesystem::path& path, const unsigned char* data,
                           size_t size);

// 16 lowercase hex digits.
std::string hex64(uint64_t v);

}  // namespace planarvo::ocl::detail
