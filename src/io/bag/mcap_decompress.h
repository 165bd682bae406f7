// A chunk's records decompressed (https://mcap.dev/spec, "Chunk"; registry "Compression formats"):
// compression "zstd" (a Zstandard frame) or "lz4" (the LZ4 *frame* format, lz4frame.h). Each
// library is optional in the build (cmake/PlanarvoCompression.cmake); without it such a chunk is
// InvalidInput naming the compression and the Debian package.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace planarvo::io::bag::mcap {

// The most a chunk may decompress to (1 GiB): one chunk holds at least one message, and no
// message planarvo reads is near that; a larger uncompressed_size is refused before anything is
// allocated.
constexpr uint64_t kMaxChunkSize = uint64_t{1} << 30;

// Replaces `out` with the decompressed bytes, which must be exactly `uncompressed_size` (the
// chunk's field, at most kMaxChunkSize). Memory grows with the output actually produced, not
// with the size the file claims. `context` starts every error message ("log.mcap: at byte 123: ").
void decompress_chunk(const std::string& compression, const uint8_t* data, size_t size,
                      uint64_t uncompressed_size, std::vector<uint8_t>& out, const std::string& context);

}  // namespace planarvo::io::bag::mcap
