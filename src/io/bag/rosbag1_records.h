// The records of a ROS bag, format 2.0 (http://wiki.ros.org/Bags/Format/2.0), for the reader in
// rosbag1.cpp: a record is `<int32 header_len><header><int32 data_len><data>`, a header is a run of
// fields `<int32 field_len><name>=<value>`, integers are little-endian. Everything read is
// checked against what remains before it is used; errors are InvalidInput naming the file and
// the byte (Place).
#pragma once
#include <cstdint>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace planarvo::io::bag::rosbag1 {

// The record kinds ("op" field) of format 2.0; 0x01 (message definition) was format 1.2's.
enum Op : uint8_t {
  kOpMessageData = 0x02,
  kOpBagHeader = 0x03,
  kOpIndexData = 0x04,
  kOpChunk = 0x05,
  kOpChunkInfo = 0x06,
  kOpConnection = 0x07,
};

// Where a byte is, for error messages: in the file, or inside a chunk's decompressed data.
struct Place {
  std::string path;
  bool in_chunk = false;
  uint64_t chunk_pos = 0;  // the chunk record's file offset, when in_chunk

  // "log.bag: at byte N" or "log.bag: in the chunk at byte C, at byte N of its data".
  std::string at(uint64_t byte) const;
  [[noreturn]] void fail(uint64_t byte, const std::string& what) const;
};

// A record header or a connection header: the fields in file order (a name given twice: the
// last one counts, as in rosbag's own readers).
class Fields {
 public:
  // Parses `size` bytes; `start` is their offset (for errors).
  Fields(const uint8_t* data, size_t size, const Place& place, uint64_t start);

  bool has(const std::string& name) const { return find(name) != nullptr; }
  const std::string* find(const std::string& name) const;
  // The field's value; a missing field or one of the wrong width is InvalidInput.
  uint8_t op() const;
  uint32_t u32(const std::string& name) const;
  uint64_t u64(const std::string& name) const;
  // A ROS time (uint32 sec, uint32 nsec) as integer nanoseconds since the epoch; fits int64.
  int64_t time_ns(const std::string& name) const;
  const std::string& str(const std::string& name) const;

 private:
  const std::string& value(const std::string& name, size_t width) const;

  std::vector<std::pair<std::string, std::string>> fields_;
  Place place_;
  uint64_t start_;
};

// The record's name for messages: "chunk", "connection", ... or "record with op 0x09".
std::string op_name(uint8_t op);

uint32_t load_u32(const uint8_t* p);
int64_t load_time_ns(const uint8_t* p);  // uint32 sec, uint32 nsec

// One record in memory (a decompressed chunk, or bytes read from the file).
struct Record {
  Fields header;
  uint64_t data_pos = 0;   // offset of the data in the buffer
  uint32_t data_size = 0;
  uint64_t end = 0;        // offset just after the record
};

// Parses the record at `pos` of buf[0..size); a record that runs past `size` is InvalidInput.
Record parse_record(const uint8_t* buf, size_t size, uint64_t pos, const Place& place);

// The bag file, read at offsets. Reads past its end are InvalidInput with the caller's words.
class BagStream {
 public:
  explicit BagStream(const std::string& path);
  uint64_t size() const { return size_; }
  const std::string& path() const { return path_; }
  // Reads n bytes at pos into dst; `what` says what they are when the file is too short.
  void read(uint64_t pos, void* dst, size_t n, const char* what);
  std::vector<uint8_t> read_vector(uint64_t pos, size_t n, const char* what);

 private:
  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
};

// A record's header read from the file at `pos`, and where its data lie (not read). A header or
// a data length that runs past the end of the file is InvalidInput "the file ends inside
// <what> at byte pos (truncated?)", naming the chunk when the op says it is one.
struct FileRecord {
  Fields header;
  uint64_t pos = 0;
  uint64_t data_pos = 0;
  uint32_t data_size = 0;
  uint64_t end = 0;
};
FileRecord read_file_record(BagStream& file, uint64_t pos, const Place& place);

}  // namespace planarvo::io::bag::rosbag1
