#include "io/bag/mcap_records.h"

#include <array>

#include "core/error.h"

namespace planarvo::io::bag::mcap {

namespace {

uint64_t load_le(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// CRC-32 (the zlib polynomial, reflected) by slicing by 8: t[0] is the byte-wise table, t[k] the
// effect of a byte followed by k zero bytes, so 8 bytes take 8 lookups and no dependency chain
// between them (about 5x the byte-wise loop; a chunk's CRC is checked whenever it is read whole).
using CrcTables = std::array<std::array<uint32_t, 256>, 8>;
CrcTables make_crc_tables() {
  CrcTables t{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (size_t k = 1; k < 8; ++k)
    for (size_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFu];
  return t;
}

uint32_t load_le32(const uint8_t* p) {
  return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24;
}

// A Map<uint16, uint64> (spec "Serialization": uint32 byte length, then key/value entries).
std::vector<std::pair<uint16_t, uint64_t>> parse_u16_u64_map(Cursor& c, const char* what) {
  Cursor entries = c.sub(c.u32(what), what);
  std::vector<std::pair<uint16_t, uint64_t>> out;
  out.reserve(entries.remaining() / 10);
  while (!entries.done()) {
    const uint16_t key = entries.u16(what);
    out.emplace_back(key, entries.u64(what));
  }
  return out;
}

}  // namespace

std::string where(const Origin& origin, uint64_t pos) {
  const std::string& path = origin.path ? *origin.path : std::string();
  if (origin.chunk == kNoChunk) return path + ": at byte " + std::to_string(origin.base + pos) + ": ";
  return path + ": in the chunk at byte " + std::to_string(origin.chunk) + ", at byte " +
         std::to_string(origin.base + pos) + " of its records: ";
}

void Cursor::fail(const std::string& message) const { fail_at(pos_, message); }

void Cursor::fail_at(size_t pos, const std::string& message) const {
  throw_invalid_input(where(origin_, pos) + message);
}

const uint8_t* Cursor::take(uint64_t n, const char* what) {
  if (n > remaining())
    fail(std::string("the ") + what + " needs " + std::to_string(n) + " bytes, only " + std::to_string(remaining()) +
         " are left in its record");
  const uint8_t* p = data_ + pos_;
  pos_ += static_cast<size_t>(n);
  return p;
}

uint8_t Cursor::u8(const char* what) { return *take(1, what); }
uint16_t Cursor::u16(const char* what) { return static_cast<uint16_t>(load_le(take(2, what), 2)); }
uint32_t Cursor::u32(const char* what) { return static_cast<uint32_t>(load_le(take(4, what), 4)); }
uint64_t Cursor::u64(const char* what) { return load_le(take(8, what), 8); }

std::string Cursor::string(const char* what) {
  const uint32_t n = u32(what);
  const uint8_t* p = take(n, what);
  return std::string(reinterpret_cast<const char*>(p), n);
}

void Cursor::skip_prefixed(const char* what) { take(u32(what), what); }

Cursor Cursor::sub(uint64_t n, const char* what) {
  const size_t start = pos_;
  const uint8_t* p = take(n, what);
  Origin o = origin_;
  o.base += start;
  return Cursor(p, static_cast<size_t>(n), o);
}

RecordPrefix parse_prefix(const uint8_t bytes[kPrefixSize]) {
  return RecordPrefix{bytes[0], load_le(bytes + 1, 8)};
}

Footer parse_footer(Cursor& c) {
  Footer f;
  f.summary_start = c.u64("footer's summary_start");
  f.summary_offset_start = c.u64("footer's summary_offset_start");
  f.summary_crc = c.u32("footer's summary_crc");
  return f;
}

Schema parse_schema(Cursor& c) {
  Schema s;
  s.id = c.u16("schema's id");
  s.name = c.string("schema's name");
  s.encoding = c.string("schema's encoding");
  c.skip_prefixed("schema's data");
  return s;
}

Channel parse_channel(Cursor& c) {
  Channel ch;
  ch.id = c.u16("channel's id");
  ch.schema_id = c.u16("channel's schema_id");
  ch.topic = c.string("channel's topic");
  ch.message_encoding = c.string("channel's message_encoding");
  c.skip_prefixed("channel's metadata");
  return ch;
}

MessageFixed parse_message_fixed(Cursor& c) {
  MessageFixed m;
  m.channel_id = c.u16("message's channel_id");
  c.u32("message's sequence");
  m.log_time = c.u64("message's log_time");
  c.u64("message's publish_time");
  return m;
}

ChunkHead parse_chunk_head(Cursor& c, uint64_t content_size) {
  ChunkHead h;
  c.u64("chunk's message_start_time");
  c.u64("chunk's message_end_time");
  h.uncompressed_size = c.u64("chunk's uncompressed_size");
  h.uncompressed_crc = c.u32("chunk's uncompressed_crc");
  h.compression = c.string("chunk's compression");
  h.records_size = c.u64("chunk's records length");
  h.records_pos = c.pos();
  if (h.records_size > content_size - h.records_pos)
    c.fail("the chunk's records (" + std::to_string(h.records_size) + " bytes) run past the end of the chunk (" +
           std::to_string(content_size - h.records_pos) + " bytes left)");
  return h;
}

MessageIndex parse_message_index(Cursor& c) {
  MessageIndex m;
  m.channel_id = c.u16("message index's channel_id");
  const size_t at = c.pos();
  Cursor entries = c.sub(c.u32("message index's records"), "message index's records");
  if (entries.remaining() % 16 != 0)
    c.fail_at(at, "a message index's records are " + std::to_string(entries.remaining()) +
                      " bytes, not a multiple of 16 (log_time, offset)");
  m.entries.reserve(entries.remaining() / 16);
  while (!entries.done()) {
    const uint64_t t = entries.u64("message index's log_time");
    m.entries.emplace_back(t, entries.u64("message index's offset"));
  }
  return m;
}

ChunkIndex parse_chunk_index(Cursor& c) {
  ChunkIndex ci;
  c.u64("chunk index's message_start_time");
  c.u64("chunk index's message_end_time");
  ci.chunk_start_offset = c.u64("chunk index's chunk_start_offset");
  ci.chunk_length = c.u64("chunk index's chunk_length");
  ci.message_index_offsets = parse_u16_u64_map(c, "chunk index's message_index_offsets");
  ci.message_index_length = c.u64("chunk index's message_index_length");
  ci.compression = c.string("chunk index's compression");
  ci.compressed_size = c.u64("chunk index's compressed_size");
  ci.uncompressed_size = c.u64("chunk index's uncompressed_size");
  return ci;
}

Statistics parse_statistics(Cursor& c) {
  Statistics s;
  c.u64("statistics' message_count");
  c.u16("statistics' schema_count");
  c.u32("statistics' channel_count");
  c.u32("statistics' attachment_count");
  c.u32("statistics' metadata_count");
  c.u32("statistics' chunk_count");
  c.u64("statistics' message_start_time");
  c.u64("statistics' message_end_time");
  s.channel_message_counts = parse_u16_u64_map(c, "statistics' channel_message_counts");
  return s;
}

uint32_t crc32(const uint8_t* data, size_t size, uint32_t crc) {
  static const CrcTables t = make_crc_tables();
  uint32_t c = crc ^ 0xFFFFFFFFu;
  size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    const uint32_t lo = c ^ load_le32(data + i), hi = load_le32(data + i + 4);
    c = t[7][lo & 0xFFu] ^ t[6][(lo >> 8) & 0xFFu] ^ t[5][(lo >> 16) & 0xFFu] ^ t[4][lo >> 24] ^
        t[3][hi & 0xFFu] ^ t[2][(hi >> 8) & 0xFFu] ^ t[1][(hi >> 16) & 0xFFu] ^ t[0][hi >> 24];
  }
  for (; i < size; ++i) c = t[0][(c ^ data[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

}  // namespace planarvo::io::bag::mcap
