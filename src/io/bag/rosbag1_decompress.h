// A ROS bag chunk's data decompressed (Bags/Format/2.0 "Chunk": compression "none", "bz2" or
// "lz4"; rosbag's lz4 is the LZ4 frame format, written by roslz4).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "io/bag/rosbag1_records.h"

namespace planarvo::io::bag::rosbag1 {

// Decompresses n bytes of a chunk whose header says `compression` and `size` (the uncompressed
// size) into `out`. The output buffer grows with what the stream actually yields (never sized by
// `size` alone); a stream that ends early, yields more or fewer than `size` bytes, has bytes
// after its end, or a compression this build lacks (naming the Debian package) is InvalidInput
// at the chunk's byte (`place` names the file, `chunk_pos` the chunk record).
void decompress_chunk(const std::string& compression, const uint8_t* data, size_t n, uint32_t size,
                      std::vector<uint8_t>& out, const Place& place, uint64_t chunk_pos);

}  // namespace planarvo::io::bag::rosbag1
