// MCAP's records (https://mcap.dev/spec, "Records" and "Serialization"), parsed from bytes in memory
// with a bounds-checked cursor: every length read from the file is checked against what remains
// of the record before it is used. Integers are little-endian; a String is a uint32 byte length
// and the bytes; a Map a uint32 byte length and its entries. Records may gain fields at their end
// ("Readers should ignore any unknown fields"), so a record longer than the fields read is fine.
//
// Errors name the file and the byte: "log.mcap: at byte 1234: ..." for bytes read from the file,
// "log.mcap: in the chunk at byte 5678, at byte 90 of its records: ..." for a chunk's records.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace planarvo::io::bag::mcap {

// Opcodes (spec "Records"); others (0x09 Attachment, 0x0A..0x0E, private 0x80-0xFF, future ones)
// are skipped by their length.
enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kDataEnd = 0x0F,
};

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
constexpr uint64_t kMagicSize = sizeof kMagic;
constexpr uint64_t kPrefixSize = 9;         // opcode (1) + content length (uint64)
constexpr uint64_t kFooterSize = 20;        // summary_start, summary_offset_start, summary_crc
constexpr uint64_t kMessageFixedSize = 22;  // channel_id, sequence, log_time, publish_time
constexpr uint64_t kNoChunk = 0;            // file offset 0 is the magic, never a chunk

// Where bytes came from, for error messages: the file (`base` is the file offset of the first
// byte) or the records of the chunk record at file offset `chunk` (`base` is then the offset
// inside its decompressed records).
struct Origin {
  const std::string* path = nullptr;
  uint64_t base = 0;
  uint64_t chunk = kNoChunk;
};

// "path: at byte N: " or "path: in the chunk at byte C, at byte N of its records: ".
std::string where(const Origin& origin, uint64_t pos);

class Cursor {
 public:
  Cursor(const uint8_t* data, size_t size, Origin origin) : data_(data), size_(size), origin_(origin) {}
  size_t pos() const { return pos_; }
  size_t remaining() const { return size_ - pos_; }
  bool done() const { return pos_ == size_; }
  uint8_t u8(const char* what);
  uint16_t u16(const char* what);
  uint32_t u32(const char* what);
  uint64_t u64(const char* what);
  std::string string(const char* what);  // uint32 length, then the bytes
  void skip_prefixed(const char* what);  // uint32 length, then bytes that are not needed
  // The next n bytes as a cursor of their own (for a Map's entries), advancing past them.
  Cursor sub(uint64_t n, const char* what);
  [[noreturn]] void fail(const std::string& message) const;
  [[noreturn]] void fail_at(size_t pos, const std::string& message) const;
  const Origin& origin() const { return origin_; }

 private:
  const uint8_t* take(uint64_t n, const char* what);
  const uint8_t* data_;
  size_t size_;
  Origin origin_;
  size_t pos_ = 0;
};

// A record's opcode and content length (spec "Records": <opcode><uint64 length><content>).
struct RecordPrefix {
  uint8_t opcode = 0;
  uint64_t length = 0;
};
RecordPrefix parse_prefix(const uint8_t bytes[kPrefixSize]);

struct Footer {  // op 0x02
  uint64_t summary_start = 0;
  uint64_t summary_offset_start = 0;
  uint32_t summary_crc = 0;
};
struct Schema {  // op 0x03; the data (the .msg text) is not kept
  uint16_t id = 0;
  std::string name;
  std::string encoding;
};
struct Channel {  // op 0x04; the metadata map is not kept
  uint16_t id = 0;
  uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
};
struct MessageFixed {  // op 0x05 without its data: channel_id, sequence, log_time, publish_time
  uint16_t channel_id = 0;
  uint64_t log_time = 0;
};
struct ChunkHead {  // op 0x06 up to its records
  uint64_t uncompressed_size = 0;
  uint32_t uncompressed_crc = 0;
  std::string compression;
  uint64_t records_size = 0;
  uint64_t records_pos = 0;  // where the records start, from the start of the content
};
struct MessageIndex {  // op 0x07
  uint16_t channel_id = 0;
  std::vector<std::pair<uint64_t, uint64_t>> entries;  // log_time, offset in the chunk's records
};
struct ChunkIndex {  // op 0x08
  uint64_t chunk_start_offset = 0;
  uint64_t chunk_length = 0;
  std::vector<std::pair<uint16_t, uint64_t>> message_index_offsets;  // channel id, file offset
  uint64_t message_index_length = 0;
  std::string compression;
  uint64_t compressed_size = 0;
  uint64_t uncompressed_size = 0;
  uint64_t record_pos = 0;  // the Chunk Index record's file offset, for error messages
};
struct Statistics {  // op 0x0B; only the per-channel counts are kept
  std::vector<std::pair<uint16_t, uint64_t>> channel_message_counts;
};

// Each parses one record's content (the cursor spans exactly the content).
Footer parse_footer(Cursor& c);
Schema parse_schema(Cursor& c);
Channel parse_channel(Cursor& c);
MessageFixed parse_message_fixed(Cursor& c);
// Parses the fields before the records (the cursor may hold only those) and checks that
// records_size fits in the record's content of `content_size` bytes.
ChunkHead parse_chunk_head(Cursor& c, uint64_t content_size);
MessageIndex parse_message_index(Cursor& c);
ChunkIndex parse_chunk_index(Cursor& c);
Statistics parse_statistics(Cursor& c);

// CRC-32 as zlib computes it (reflected polynomial 0xEDB88320), the spec's "CRC32"; continue a
// running value by passing the previous result as `crc`.
uint32_t crc32(const uint8_t* data, size_t size, uint32_t crc = 0);

}  // namespace planarvo::io::bag::mcap
