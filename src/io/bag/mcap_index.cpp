// MCAP files: finding the messages of the topics asked for, by a scan of the data section or
// through the summary's Chunk Index and the Message Index records (mcap_reader.h says when each).
#include <algorithm>
#include <tuple>

#include "core/error.h"
#include "io/bag/mcap_decompress.h"
#include "io/bag/mcap_reader.h"

namespace planarvo::io::bag::mcap {

namespace {

// The Chunk record's fields before its records: 32 fixed bytes, the compression string, the
// records' uint64 length.
constexpr uint64_t kChunkFixedSize = 8 + 8 + 8 + 4;
constexpr uint64_t kChunkHeadMin = kChunkFixedSize + 4 + 8;

bool is_wanted(const std::vector<bool>& wanted, uint16_t channel) {
  return channel < wanted.size() && wanted[channel];
}

}  // namespace

// A Message record's place; its log_time must fit the signed nanoseconds of MessageRef.
Found Reader::message_found(const MessageFixed& m, uint64_t record_length, const Cursor& c, size_t pos) const {
  if (m.log_time > static_cast<uint64_t>(INT64_MAX))
    c.fail_at(pos, "a message's log_time (" + std::to_string(m.log_time) + ") is beyond the year 2262 (over INT64_MAX ns)");
  const uint64_t size = record_length - kMessageFixedSize;
  if (size > UINT32_MAX) c.fail_at(pos, "a message of " + std::to_string(size) + " bytes (over 4 GiB)");
  if (channels_.find(m.channel_id) == channels_.end())
    c.fail_at(pos, "a message on channel " + std::to_string(m.channel_id) + ", which no earlier Channel record defines");
  Found f;
  f.log_time = m.log_time;
  f.channel = m.channel_id;
  f.size = static_cast<uint32_t>(size);
  if (c.origin().chunk == kNoChunk) {
    f.file_pos = c.origin().base + pos;
    f.offset = f.file_pos + kPrefixSize + kMessageFixedSize;
  } else {
    f.file_pos = f.location = c.origin().chunk;
    f.inner_pos = c.origin().base + pos;
    f.offset = f.inner_pos + kPrefixSize + kMessageFixedSize;
  }
  return f;
}

// Spec "Chunk": reads the fields before the records of the Chunk record at `pos` and remembers
// where its records are.
ChunkPlace& Reader::chunk_at(uint64_t pos, const RecordPrefix& prefix) {
  const auto known = chunks_.find(pos);
  if (known != chunks_.end()) return known->second;
  const std::string at = where(at_file(pos), 0);
  if (prefix.length < kChunkHeadMin) throw_invalid_input(at + "a Chunk record too short for its fields");
  uint8_t fixed[kChunkFixedSize + 4];
  read_exact(pos + kPrefixSize, sizeof fixed, fixed);
  Cursor length_cursor(fixed + kChunkFixedSize, 4, at_file(pos + kPrefixSize + kChunkFixedSize));
  const uint32_t compression_length = length_cursor.u32("chunk's compression");
  if (compression_length > prefix.length - kChunkHeadMin)
    throw_invalid_input(at + "the chunk's compression string runs past the chunk");
  std::vector<uint8_t> head(static_cast<size_t>(kChunkHeadMin + compression_length));
  read_exact(pos + kPrefixSize, head.size(), head.data());
  Cursor c(head.data(), head.size(), at_file(pos + kPrefixSize));
  const ChunkHead h = parse_chunk_head(c, prefix.length);
  if (h.compression.empty() && h.uncompressed_size != h.records_size)
    throw_invalid_input(at + "an uncompressed chunk whose uncompressed_size (" + std::to_string(h.uncompressed_size) +
                        ") is not its records' size (" + std::to_string(h.records_size) + ")");
  ChunkPlace place{pos + kPrefixSize + h.records_pos, h.records_size, h.uncompressed_size, h.uncompressed_crc,
                   h.compression};
  return chunks_.emplace(pos, std::move(place)).first->second;
}

// The chunk's records in memory (decompressed; its CRC checked when it has one), kept until
// another chunk is needed.
const std::vector<uint8_t>& Reader::chunk_records(uint64_t pos) {
  if (cached_chunk_ == pos) return cached_;
  const ChunkPlace& place = chunks_.at(pos);
  cached_chunk_ = kNoChunk;
  const std::string at = where(at_file(pos), 0);
  if (place.compression.empty()) {
    cached_.resize(static_cast<size_t>(place.records_size));  // inside the file: chunk_at checked it
    read_exact(place.records_offset, place.records_size, cached_.data());
  } else {
    scratch_.resize(static_cast<size_t>(place.records_size));
    read_exact(place.records_offset, place.records_size, scratch_.data());
    decompress_chunk(place.compression, scratch_.data(), scratch_.size(), place.uncompressed_size, cached_, at);
  }
  if (place.crc != 0 && crc32(cached_.data(), cached_.size()) != place.crc)
    throw_invalid_input(at + "the chunk's records do not match its uncompressed_crc (a corrupt file)");
  cached_chunk_ = pos;
  return cached_;
}

// Walks the records of the chunk at `pos`: Schema and Channel records are defined, the messages
// (all in Mode::Scan, the wanted channels' in Mode::Indexed) appended to `out`.
void Reader::walk_chunk(uint64_t pos, Mode mode, const std::vector<bool>& wanted, std::vector<Found>& out) {
  const std::vector<uint8_t>& records = chunk_records(pos);
  Cursor c(records.data(), records.size(), Origin{&path_, 0, pos});
  while (!c.done()) {
    const size_t at = c.pos();
    const uint8_t opcode = c.u8("record's opcode");
    const uint64_t length = c.u64("record's length");
    Cursor body = c.sub(length, "record");
    if (opcode == kSchema) add_schema(parse_schema(body), c, at);
    if (opcode == kChannel) add_channel(parse_channel(body), c, at, mode);
    if (opcode == kMessage) {
      const MessageFixed m = parse_message_fixed(body);
      if (mode == Mode::Scan || is_wanted(wanted, m.channel_id)) out.push_back(message_found(m, length, c, at));
    }
  }
}

// Spec "Data Section": every record from the Header to the Data End record (or a Footer, or the
// end of the file between two records). Keeps every message in all_ and defines the channels.
void Reader::scan(const IndexProgress& progress) {
  std::vector<Found> found;
  const std::vector<bool> none;
  uint64_t pos = data_start_;
  while (pos < data_end_) {
    cancel_if_asked(progress, static_cast<double>(pos) / static_cast<double>(data_end_));
    const RecordPrefix prefix = read_prefix(pos, data_end_);
    if (prefix.opcode == kDataEnd || prefix.opcode == kFooter) break;
    if (prefix.opcode == kSchema || prefix.opcode == kChannel || prefix.opcode == kMessage) {
      // A message's data are not read: only its fixed fields.
      const uint64_t n = prefix.opcode == kMessage ? std::min(prefix.length, kMessageFixedSize) : prefix.length;
      std::vector<uint8_t> content(static_cast<size_t>(n));
      read_exact(pos + kPrefixSize, n, content.data());
      Cursor body(content.data(), content.size(), at_file(pos + kPrefixSize));
      const Cursor record(nullptr, 0, at_file(pos));
      if (prefix.opcode == kSchema) add_schema(parse_schema(body), record, 0);
      if (prefix.opcode == kChannel) add_channel(parse_channel(body), record, 0, Mode::Scan);
      if (prefix.opcode == kMessage) found.push_back(message_found(parse_message_fixed(body), prefix.length, record, 0));
    }
    if (prefix.opcode == kChunk) {
      chunk_at(pos, prefix);
      walk_chunk(pos, Mode::Scan, none, found);
    }
    pos += kPrefixSize + prefix.length;
  }
  all_ = std::move(found);
  scanned_ = true;
}

// Spec "Message Index": the messages of the wanted channels in an uncompressed chunk, each
// checked against its Message record's header in the file.
void Reader::by_message_index(const ChunkIndex& ci, const ChunkPlace& place, const std::vector<bool>& wanted,
                              std::vector<Found>& out) {
  const uint64_t index_end = ci.chunk_start_offset + ci.chunk_length + ci.message_index_length;
  const uint64_t head = kPrefixSize + kMessageFixedSize;
  for (const auto& [channel, offset] : ci.message_index_offsets) {
    if (!is_wanted(wanted, channel)) continue;
    const RecordPrefix prefix = read_prefix(offset, index_end);
    const Cursor record(nullptr, 0, at_file(offset));
    if (prefix.opcode != kMessageIndex)
      record.fail("the chunk index points here for channel " + std::to_string(channel) +
                  "'s message index, but the record here is not one (opcode " + std::to_string(prefix.opcode) + ")");
    const std::vector<uint8_t> content = read_content(offset, prefix);
    Cursor body(content.data(), content.size(), at_file(offset + kPrefixSize));
    const MessageIndex index = parse_message_index(body);
    if (index.channel_id != channel)
      record.fail("a message index of channel " + std::to_string(index.channel_id) +
                  " where the chunk index says channel " + std::to_string(channel));
    for (const auto& [log_time, inner] : index.entries) {
      const Cursor in_chunk(nullptr, 0, Origin{&path_, inner, ci.chunk_start_offset});
      if (place.records_size < head || inner > place.records_size - head)
        record.fail("a message index entry (offset " + std::to_string(inner) + ") outside its chunk's records");
      uint8_t bytes[head];
      read_exact(place.records_offset + inner, head, bytes);
      const RecordPrefix mp = parse_prefix(bytes);
      if (mp.opcode != kMessage || mp.length < kMessageFixedSize || mp.length > place.records_size - inner - kPrefixSize)
        in_chunk.fail("the message index of channel " + std::to_string(channel) +
                      " points here, but there is no Message record of a fitting length");
      Cursor fixed(bytes + kPrefixSize, kMessageFixedSize, Origin{&path_, inner + kPrefixSize, ci.chunk_start_offset});
      const MessageFixed m = parse_message_fixed(fixed);
      if (m.channel_id != channel || m.log_time != log_time)
        in_chunk.fail("the message index of channel " + std::to_string(channel) + " (log_time " +
                      std::to_string(log_time) + ") disagrees with the message here (channel " +
                      std::to_string(m.channel_id) + ", log_time " + std::to_string(m.log_time) + ")");
      out.push_back(message_found(m, mp.length, in_chunk, 0));
    }
  }
}

// Spec "Chunk Index": only the chunks holding a wanted channel are read.
std::vector<Found> Reader::by_chunk_indexes(const std::vector<bool>& wanted, const IndexProgress& progress) {
  std::vector<Found> found;
  for (size_t i = 0; i < chunk_indexes_.size(); ++i) {
    cancel_if_asked(progress, static_cast<double>(i) / static_cast<double>(chunk_indexes_.size()));
    const ChunkIndex& ci = chunk_indexes_[i];
    const auto& offsets = ci.message_index_offsets;
    const bool indexed = !offsets.empty();
    if (indexed && std::none_of(offsets.begin(), offsets.end(), [&](const auto& e) { return is_wanted(wanted, e.first); }))
      continue;
    const RecordPrefix prefix = read_prefix(ci.chunk_start_offset, data_end_);
    if (prefix.opcode != kChunk || prefix.length != ci.chunk_length - kPrefixSize)
      throw_invalid_input(where(at_file(ci.record_pos), 0) + "a chunk index points at byte " +
                          std::to_string(ci.chunk_start_offset) + ", where there is no Chunk record of " +
                          std::to_string(ci.chunk_length) + " bytes");
    const ChunkPlace& place = chunk_at(ci.chunk_start_offset, prefix);
    const size_t first = found.size();
    if (indexed && place.compression.empty()) {
      by_message_index(ci, place, wanted, found);
    } else {
      walk_chunk(ci.chunk_start_offset, Mode::Indexed, wanted, found);
    }
    // A message listed twice by a corrupt index would be handed out twice.
    std::sort(found.begin() + static_cast<std::ptrdiff_t>(first), found.end(),
              [](const Found& a, const Found& b) { return a.inner_pos < b.inner_pos; });
    const auto twice = std::adjacent_find(found.begin() + static_cast<std::ptrdiff_t>(first), found.end(),
                                          [](const Found& a, const Found& b) { return a.inner_pos == b.inner_pos; });
    if (twice != found.end())
      throw_invalid_input(where(Origin{&path_, twice->inner_pos, ci.chunk_start_offset}, 0) +
                          "the message index lists this message twice");
  }
  return found;
}

// Spec "Statistics": channel_message_counts, when the file has them, must match what the chunk
// indexes gave for every wanted channel (a channel missing from a non-empty map has none).
bool Reader::statistics_agree(const std::vector<Found>& found, const std::vector<bool>& wanted) const {
  if (stat_counts_.empty()) return true;
  std::map<uint16_t, uint64_t> counted;
  for (const Found& f : found) ++counted[f.channel];
  for (const auto& [id, info] : channels_) {
    if (!is_wanted(wanted, id)) continue;
    const auto s = stat_counts_.find(id);
    const auto n = counted.find(id);
    if ((s == stat_counts_.end() ? 0 : s->second) != (n == counted.end() ? 0 : n->second)) return false;
  }
  return true;
}

std::vector<MessageRef> Reader::index(const std::vector<uint32_t>& topics, const IndexProgress& progress) {
  if (!scan_error_.empty()) throw_invalid_input(scan_error_);
  std::vector<bool> asked(topics_.size(), false);
  for (const uint32_t t : topics) {
    check_asked(t);
    asked[t] = true;
  }
  std::vector<bool> wanted(size_t{UINT16_MAX} + 1, false);
  for (const auto& [id, info] : channels_)  // a channel of a cancelled scan has no topic yet
    if (info.topic != kNoTopic) wanted[id] = asked[info.topic];

  std::vector<Found> found;
  bool need_scan = !scanned_;
  if (need_scan && !chunk_indexes_.empty()) {
    found = by_chunk_indexes(wanted, progress);
    need_scan = !statistics_agree(found, wanted);
  }
  if (need_scan) {  // no chunk indexes, or they disagree with the statistics
    try {
      scan(progress);
      assign_topics();
    } catch (const Error& e) {
      // Channels found before the bad record are half defined: every later index() fails alike.
      if (e.code() == ErrorCode::InvalidInput) scan_error_ = e.what();
      throw;
    }
    asked.resize(topics_.size(), false);  // channels the scan found that the summary lacked
  }
  if (scanned_) {
    found.clear();
    for (const Found& f : all_)
      if (asked[channels_.at(f.channel).topic]) found.push_back(f);
  }
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    return std::tie(a.log_time, a.file_pos, a.inner_pos) < std::tie(b.log_time, b.file_pos, b.inner_pos);
  });
  std::vector<MessageRef> refs;
  refs.reserve(found.size());
  for (uint32_t t : topics) topics_[t].count = 0;
  for (const Found& f : found) {
    const uint32_t topic = channels_.at(f.channel).topic;
    ++topics_[topic].count;
    refs.push_back(MessageRef{static_cast<int64_t>(f.log_time), topic, f.location, f.offset, f.size});
  }
  if (progress) progress(1.0);
  return refs;
}

}  // namespace planarvo::io::bag::mcap
