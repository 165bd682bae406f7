// Records and header fields of the ROS bag format 2.0 (http://wiki.ros.org/Bags/Format/2.0,
// sections "Records" and "Headers").
#include "io/bag/rosbag1_records.h"

#include <cstdio>
#include <cstring>

#include "core/error.h"

namespace planarvo::io::bag::rosbag1 {

std::string Place::at(uint64_t byte) const {
  if (!in_chunk) return path + ": at byte " + std::to_string(byte);
  return path + ": in the chunk at byte " + std::to_string(chunk_pos) + ", at byte " + std::to_string(byte) +
         " of its data";
}

void Place::fail(uint64_t byte, const std::string& what) const { throw_invalid_input(at(byte) + ": " + what); }

uint32_t load_u32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}

// Bags/Format/2.0 "Conventions": time is uint32 sec then uint32 nsec. The largest value,
// (2^32 - 1) * 1e9 + 2^32 - 1 ns, fits int64; an nsec of 1e9 or more is kept as written.
int64_t load_time_ns(const uint8_t* p) {
  return static_cast<int64_t>(load_u32(p)) * 1000000000 + static_cast<int64_t>(load_u32(p + 4));
}

std::string op_name(uint8_t op) {
  switch (op) {
    case kOpMessageData: return "message data record";
    case kOpBagHeader: return "bag header record";
    case kOpIndexData: return "index data record";
    case kOpChunk: return "chunk";
    case kOpChunkInfo: return "chunk info record";
    case kOpConnection: return "connection record";
    default: break;
  }
  char buf[48];
  std::snprintf(buf, sizeof buf, "record with op 0x%02x", static_cast<unsigned>(op));
  return buf;
}

// "Headers": a header is a sequence of `<int32 field_len><name>=<value>`; the value is bytes.
Fields::Fields(const uint8_t* data, size_t size, const Place& place, uint64_t start) : place_(place), start_(start) {
  size_t pos = 0;
  while (pos < size) {
    if (size - pos < 4) place_.fail(start + pos, "a header field's length runs past the end of the header");
    const uint32_t len = load_u32(data + pos);
    pos += 4;
    if (len > size - pos)
      place_.fail(start + pos - 4, "a header field of " + std::to_string(len) +
                                       " bytes runs past the end of the header (" + std::to_string(size - pos) +
                                       " bytes left)");
    const char* field = reinterpret_cast<const char*>(data + pos);
    const void* eq = std::memchr(field, '=', len);
    if (!eq) place_.fail(start + pos - 4, "a header field without '=' (not name=value)");
    const size_t name_len = static_cast<size_t>(static_cast<const char*>(eq) - field);
    fields_.emplace_back(std::string(field, name_len), std::string(field + name_len + 1, len - name_len - 1));
    pos += len;
  }
}

const std::string* Fields::find(const std::string& name) const {
  for (auto it = fields_.rbegin(); it != fields_.rend(); ++it)
    if (it->first == name) return &it->second;
  return nullptr;
}

const std::string& Fields::value(const std::string& name, size_t width) const {
  const std::string* v = find(name);
  if (!v) place_.fail(start_, "the record header has no field '" + name + "'");
  if (width != 0 && v->size() != width)
    place_.fail(start_, "the record header's field '" + name + "' has " + std::to_string(v->size()) +
                            " bytes, not " + std::to_string(width));
  return *v;
}

uint8_t Fields::op() const { return static_cast<uint8_t>(value("op", 1)[0]); }

uint32_t Fields::u32(const std::string& name) const {
  return load_u32(reinterpret_cast<const uint8_t*>(value(name, 4).data()));
}

uint64_t Fields::u64(const std::string& name) const {
  const auto* p = reinterpret_cast<const uint8_t*>(value(name, 8).data());
  return static_cast<uint64_t>(load_u32(p)) | static_cast<uint64_t>(load_u32(p + 4)) << 32;
}

int64_t Fields::time_ns(const std::string& name) const {
  return load_time_ns(reinterpret_cast<const uint8_t*>(value(name, 8).data()));
}

const std::string& Fields::str(const std::string& name) const { return value(name, 0); }

// "Records": <header_len><header><data_len><data>.
Record parse_record(const uint8_t* buf, size_t size, uint64_t pos, const Place& place) {
  if (pos > size || size - pos < 4) place.fail(pos, "a record's header length runs past the end");
  const uint32_t header_len = load_u32(buf + pos);
  const uint64_t header_pos = pos + 4;
  if (header_len > size - header_pos || size - header_pos - header_len < 4)
    place.fail(pos, "a record header of " + std::to_string(header_len) + " bytes runs past the end (" +
                        std::to_string(size - header_pos) + " bytes left)");
  Record r{Fields(buf + header_pos, header_len, place, pos), 0, 0, 0};
  const uint64_t len_pos = header_pos + header_len;
  r.data_size = load_u32(buf + len_pos);
  r.data_pos = len_pos + 4;
  if (r.data_size > size - r.data_pos)
    place.fail(pos, "the " + op_name(r.header.op()) + "'s data of " + std::to_string(r.data_size) +
                        " bytes run past the end (" + std::to_string(size - r.data_pos) + " bytes left)");
  r.end = r.data_pos + r.data_size;
  return r;
}

BagStream::BagStream(const std::string& path) : path_(path), in_(path, std::ios::binary) {
  if (!in_) throw_invalid_input(path + ": the file cannot be opened");
  in_.seekg(0, std::ios::end);
  const std::streamoff end = in_.tellg();
  if (end < 0) throw_invalid_input(path + ": the file's size cannot be read");
  size_ = static_cast<uint64_t>(end);
}

void BagStream::read(uint64_t pos, void* dst, size_t n, const char* what) {
  if (pos > size_ || n > size_ - pos)
    throw_invalid_input(path_ + ": at byte " + std::to_string(pos) + ": the file ends inside " + what +
                        " (truncated?)");
  if (n == 0) return;
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(pos));
  in_.read(static_cast<char*>(dst), static_cast<std::streamsize>(n));
  if (static_cast<size_t>(in_.gcount()) != n)
    throw_invalid_input(path_ + ": at byte " + std::to_string(pos) + ": reading " + what + " failed");
}

std::vector<uint8_t> BagStream::read_vector(uint64_t pos, size_t n, const char* what) {
  if (pos > size_ || n > size_ - pos) read(pos, nullptr, n, what);  // throws, naming `what`
  std::vector<uint8_t> out(n);
  read(pos, out.data(), n, what);
  return out;
}

FileRecord read_file_record(BagStream& file, uint64_t pos, const Place& place) {
  const auto truncated = [&](const std::string& what) {
    throw_invalid_input(file.path() + ": the file ends inside " + what + " at byte " + std::to_string(pos) +
                        " (truncated?)");
  };
  const uint64_t size = file.size();
  uint8_t len[4];
  if (pos > size || size - pos < 4) truncated("a record");
  file.read(pos, len, 4, "a record");
  const uint32_t header_len = load_u32(len);
  if (header_len > size - pos - 4) truncated("a record");
  const std::vector<uint8_t> header = file.read_vector(pos + 4, header_len, "a record");
  FileRecord r{Fields(header.data(), header.size(), place, pos), pos, 0, 0, 0};
  const uint8_t op = r.header.op();
  const std::string what = op == kOpChunk ? "a chunk" : "a " + op_name(op);
  const uint64_t len_pos = pos + 4 + header_len;
  if (size - len_pos < 4) truncated(what);
  file.read(len_pos, len, 4, what.c_str());
  r.data_size = load_u32(len);
  r.data_pos = len_pos + 4;
  if (r.data_size > size - r.data_pos) truncated(what);
  r.end = r.data_pos + r.data_size;
  return r;
}

}  // namespace planarvo::io::bag::rosbag1
