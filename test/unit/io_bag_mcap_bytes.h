// Hand-built bytes for the bag reader tests: MCAP records (https://mcap.dev/spec, little-endian,
// String = uint32 length + bytes) and ROS 2 CDR messages (4-byte encapsulation header, each
// primitive aligned to its size from the end of it), written here independently of the readers.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace planarvo_test {

inline void put_le(std::vector<uint8_t>& b, uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

inline void put_string(std::vector<uint8_t>& b, const std::string& s) {
  put_le(b, s.size(), 4);
  b.insert(b.end(), s.begin(), s.end());
}

inline uint32_t test_crc32(const std::vector<uint8_t>& data) {  // zlib's CRC-32, bit by bit
  uint32_t c = 0xFFFFFFFFu;
  for (uint8_t byte : data) {
    c ^= byte;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

// An MCAP file (or a chunk's records) built record by record.
struct McapBytes {
  std::vector<uint8_t> bytes;

  // The magic and a Header record (profile "", library ""): 8 + 9 + 8 = 25 bytes.
  static McapBytes file() {
    McapBytes f;
    f.bytes = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
    f.record(0x01, std::vector<uint8_t>(8, 0));
    return f;
  }
  void record(uint8_t opcode, const std::vector<uint8_t>& content) {
    bytes.push_back(opcode);
    put_le(bytes, content.size(), 8);
    bytes.insert(bytes.end(), content.begin(), content.end());
  }
  void schema(uint16_t id, const std::string& name) {
    std::vector<uint8_t> c;
    put_le(c, id, 2);
    put_string(c, name);
    put_string(c, "ros2msg");
    put_le(c, 0, 4);
    record(0x03, c);
  }
  void channel(uint16_t id, uint16_t schema_id, const std::string& topic, const std::string& encoding = "cdr") {
    std::vector<uint8_t> c;
    put_le(c, id, 2);
    put_le(c, schema_id, 2);
    put_string(c, topic);
    put_string(c, encoding);
    put_le(c, 0, 4);
    record(0x04, c);
  }
  void message(uint16_t channel_id, uint64_t log_time, const std::vector<uint8_t>& data) {
    std::vector<uint8_t> c;
    put_le(c, channel_id, 2);
    put_le(c, 0, 4);
    put_le(c, log_time, 8);
    put_le(c, log_time, 8);
    c.insert(c.end(), data.begin(), data.end());
    record(0x05, c);
  }
  // A Chunk of `records` stored as they are (compression names what the field says).
  void chunk(const std::vector<uint8_t>& records, bool with_crc, uint32_t crc_override = 0,
             const std::string& compression = "") {
    std::vector<uint8_t> c;
    put_le(c, 0, 8);
    put_le(c, 0, 8);
    put_le(c, records.size(), 8);
    put_le(c, crc_override ? crc_override : with_crc ? test_crc32(records) : 0, 4);
    put_string(c, compression);
    put_le(c, records.size(), 8);
    c.insert(c.end(), records.begin(), records.end());
    record(0x06, c);
  }
  // A Chunk Index of the chunk record at `offset` (`length` bytes), without message indexes.
  void chunk_index(uint64_t offset, uint64_t length, uint64_t records_size) {
    std::vector<uint8_t> c;
    put_le(c, 0, 8);
    put_le(c, 0, 8);
    put_le(c, offset, 8);
    put_le(c, length, 8);
    put_le(c, 0, 4);  // message_index_offsets: none
    put_le(c, 0, 8);
    put_string(c, "");
    put_le(c, records_size, 8);
    put_le(c, records_size, 8);
    record(0x08, c);
  }
  void statistics(uint16_t channel, uint64_t count) {
    std::vector<uint8_t> c;
    put_le(c, count, 8);
    put_le(c, 1, 2);
    put_le(c, 1, 4);
    put_le(c, 0, 4);  // attachment_count
    put_le(c, 0, 4);  // metadata_count
    put_le(c, 0, 4);  // chunk_count
    put_le(c, 0, 8);
    put_le(c, 0, 8);
    put_le(c, 10, 4);
    put_le(c, channel, 2);
    put_le(c, count, 8);
    record(0x0B, c);
  }
  void footer(uint64_t summary_start, uint64_t summary_offset_start, uint32_t crc) {
    std::vector<uint8_t> c;
    put_le(c, summary_start, 8);
    put_le(c, summary_offset_start, 8);
    put_le(c, crc, 4);
    record(0x02, c);
    bytes.insert(bytes.end(), {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'});
  }
};

// A CDR message: the encapsulation header, then fields aligned to their size.
struct CdrBytes {
  explicit CdrBytes(bool little = true) : little_(little), bytes{0x00, uint8_t(little ? 1 : 0), 0, 0} {}
  void align(size_t n) {
    while ((bytes.size() - 4) % n) bytes.push_back(0);
  }
  void put(uint64_t v, int n) {
    align(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) bytes.push_back(static_cast<uint8_t>(v >> (8 * (little_ ? i : n - 1 - i))));
  }
  CdrBytes& u8(uint8_t v) { put(v, 1); return *this; }
  CdrBytes& u32(uint32_t v) { put(v, 4); return *this; }
  CdrBytes& i32(int32_t v) { put(static_cast<uint32_t>(v), 4); return *this; }
  CdrBytes& f64(double v) {
    uint64_t u;
    std::memcpy(&u, &v, sizeof u);
    put(u, 8);
    return *this;
  }
  CdrBytes& str(const std::string& s) {
    u32(static_cast<uint32_t>(s.size() + 1));
    bytes.insert(bytes.end(), s.begin(), s.end());
    bytes.push_back(0);
    return *this;
  }
  CdrBytes& seq(const std::vector<uint8_t>& v) {
    u32(static_cast<uint32_t>(v.size()));
    bytes.insert(bytes.end(), v.begin(), v.end());
    return *this;
  }
  CdrBytes& header(int32_t sec, uint32_t nanosec, const std::string& frame) { return i32(sec).u32(nanosec).str(frame); }

  bool little_;
  std::vector<uint8_t> bytes;
};

}  // namespace planarvo_test
