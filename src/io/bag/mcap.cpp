// MCAP files (https://mcap.dev/spec): opening, the summary section, channels and topics, and
// reading one message back. mcap_reader.h says how a file is read; mcap_index.cpp finds messages.
#include <algorithm>
#include <cstring>

#include "core/error.h"
#include "io/bag/bag.h"
#include "io/bag/mcap_reader.h"
#include "io/bag/messages.h"

namespace planarvo::io::bag {

namespace mcap {

Reader::Reader(const std::string& path) : path_(path) {
  file_.open(path, std::ios::binary);
  if (!file_) throw_invalid_input(path + ": the file cannot be opened");
  file_.seekg(0, std::ios::end);
  const std::streamoff size = file_.tellg();
  if (size < 0) throw_invalid_input(path + ": the file's size cannot be read");
  file_size_ = static_cast<uint64_t>(size);
  data_end_ = file_size_;
  read_header();
  if (!read_summary()) scan({});
  assign_topics();
}

// Spec "Magic" and "Header": the magic, then a Header record (profile, library; not needed).
void Reader::read_header() {
  uint8_t magic[kMagicSize] = {};
  if (file_size_ < kMagicSize) throw_invalid_input(path_ + ": not an MCAP file: shorter than its magic bytes");
  read_exact(0, kMagicSize, magic);
  if (std::memcmp(magic, kMagic, kMagicSize) != 0)
    throw_invalid_input(path_ + ": not an MCAP file: its first bytes are not the MCAP magic");
  const RecordPrefix header = read_prefix(kMagicSize, file_size_);
  if (header.opcode != kHeader)
    throw_invalid_input(where(at_file(kMagicSize), 0) + "the first record is not a Header (opcode " +
                        std::to_string(header.opcode) + ")");
  data_start_ = kMagicSize + kPrefixSize + header.length;
}

void Reader::read_exact(uint64_t offset, uint64_t size, uint8_t* out) {
  if (offset > file_size_ || size > file_size_ - offset)
    throw_invalid_input(where(at_file(offset), 0) + "the file ends inside a record (truncated?)");
  if (size == 0) return;
  file_.clear();
  file_.seekg(static_cast<std::streamoff>(offset));
  file_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(size));
  if (!file_ || static_cast<uint64_t>(file_.gcount()) != size)
    throw_invalid_input(where(at_file(offset), 0) + std::to_string(size) + " bytes cannot be read");
}

// The record at `offset` must end by `end` (the file's end or its section's).
RecordPrefix Reader::read_prefix(uint64_t offset, uint64_t end) {
  const bool file_end = end == file_size_;
  if (offset > end || end - offset < kPrefixSize)
    throw_invalid_input(where(at_file(offset), 0) +
                        (file_end ? "the file ends inside a record (truncated?)" : "a record runs past its section"));
  uint8_t bytes[kPrefixSize];
  read_exact(offset, kPrefixSize, bytes);
  const RecordPrefix p = parse_prefix(bytes);
  if (p.length > end - offset - kPrefixSize)
    throw_invalid_input(where(at_file(offset), 0) +
                        (file_end ? "the file ends inside a record (truncated?)"
                                  : "a record of " + std::to_string(p.length) + " bytes runs past its section"));
  return p;
}

std::vector<uint8_t> Reader::read_content(uint64_t offset, const RecordPrefix& prefix) {
  std::vector<uint8_t> content(static_cast<size_t>(prefix.length));  // read_prefix checked it is in the file
  read_exact(offset + kPrefixSize, prefix.length, content.data());
  return content;
}

// Spec "Footer", "Summary Section": false when there is no summary to use.
bool Reader::read_summary() {
  constexpr uint64_t footer_record = kPrefixSize + kFooterSize;
  if (file_size_ < data_start_ || file_size_ - data_start_ < footer_record + kMagicSize) return false;
  uint8_t tail[footer_record + kMagicSize];
  const uint64_t footer_pos = file_size_ - sizeof tail;
  read_exact(footer_pos, sizeof tail, tail);
  const RecordPrefix prefix = parse_prefix(tail);
  if (std::memcmp(tail + footer_record, kMagic, kMagicSize) != 0 || prefix.opcode != kFooter ||
      prefix.length != kFooterSize)
    return false;  // cut off before its end: scanned
  Cursor fc(tail + kPrefixSize, kFooterSize, at_file(footer_pos + kPrefixSize));
  const Footer footer = parse_footer(fc);
  if (footer.summary_start == 0) return false;
  const uint64_t summary_end = footer.summary_offset_start != 0 ? footer.summary_offset_start : footer_pos;
  if (footer.summary_start < data_start_ || footer.summary_start > summary_end || summary_end > footer_pos)
    throw_invalid_input(where(at_file(footer_pos), 0) + "the footer's summary_start (" +
                        std::to_string(footer.summary_start) + ") or summary_offset_start (" +
                        std::to_string(footer.summary_offset_start) + ") is outside the file's data after its header");
  if (footer.summary_crc != 0) check_summary_crc(footer.summary_start, footer_pos, footer.summary_crc);

  std::vector<uint8_t> summary(static_cast<size_t>(summary_end - footer.summary_start));
  read_exact(footer.summary_start, summary.size(), summary.data());
  Cursor c(summary.data(), summary.size(), at_file(footer.summary_start));
  std::vector<ChunkIndex> chunk_indexes;
  while (!c.done()) {
    const size_t pos = c.pos();
    const uint8_t opcode = c.u8("record's opcode");
    Cursor body = c.sub(c.u64("record's length"), "summary record");
    if (opcode == kSchema) add_schema(parse_schema(body), c, pos);
    if (opcode == kChannel) add_channel(parse_channel(body), c, pos, Mode::Scan);
    if (opcode == kChunkIndex) {
      chunk_indexes.push_back(parse_chunk_index(body));
      chunk_indexes.back().record_pos = footer.summary_start + pos;
    }
    if (opcode == kStatistics)
      for (const auto& [id, count] : parse_statistics(body).channel_message_counts) stat_counts_[id] = count;
  }
  data_end_ = footer.summary_start;
  if (channels_.empty()) {  // nothing to list the topics with: scanned (what was read is dropped)
    schemas_.clear();
    stat_counts_.clear();
    return false;
  }
  for (const ChunkIndex& ci : chunk_indexes) check_chunk_index(ci);
  std::stable_sort(chunk_indexes.begin(), chunk_indexes.end(), [](const ChunkIndex& a, const ChunkIndex& b) {
    return a.chunk_start_offset < b.chunk_start_offset;
  });
  // One index per chunk, chunks apart (else one chunk could be read again and again).
  for (size_t i = 1; i < chunk_indexes.size(); ++i)
    if (chunk_indexes[i].chunk_start_offset - chunk_indexes[i - 1].chunk_start_offset < chunk_indexes[i - 1].chunk_length)
      throw_invalid_input(where(at_file(chunk_indexes[i].record_pos), 0) + "a chunk index points at byte " +
                          std::to_string(chunk_indexes[i].chunk_start_offset) +
                          ", inside the chunk that another chunk index points at");
  chunk_indexes_ = std::move(chunk_indexes);
  return true;
}

// Footer's summary_crc: the CRC-32 of the summary section, the summary offset section and the
// footer up to and including summary_offset_start.
void Reader::check_summary_crc(uint64_t summary_start, uint64_t footer_pos, uint32_t expected) {
  const uint64_t end = footer_pos + kPrefixSize + 16;
  std::vector<uint8_t> block(1 << 16);
  uint32_t crc = 0;
  for (uint64_t at = summary_start; at < end;) {
    const uint64_t n = std::min<uint64_t>(block.size(), end - at);
    read_exact(at, n, block.data());
    crc = crc32(block.data(), static_cast<size_t>(n), crc);
    at += n;
  }
  if (crc != expected)
    throw_invalid_input(where(at_file(summary_start), 0) + "the summary section does not match the footer's CRC " +
                        "(a corrupt file)");
}

// Spec "Chunk Index": the chunk and its message index records must lie in the data section.
void Reader::check_chunk_index(const ChunkIndex& ci) const {
  const std::string at = where(at_file(ci.record_pos), 0) + "a chunk index ";
  const uint64_t start = ci.chunk_start_offset;
  if (start < data_start_ || start > data_end_ || ci.chunk_length < kPrefixSize ||
      ci.chunk_length > data_end_ - start)
    throw_invalid_input(at + "points at a chunk (at byte " + std::to_string(start) + ", " +
                        std::to_string(ci.chunk_length) + " bytes) outside the data section");
  const uint64_t index_start = start + ci.chunk_length;
  if (ci.message_index_length > data_end_ - index_start)
    throw_invalid_input(at + "has message index records running past the data section");
  for (const auto& [channel, offset] : ci.message_index_offsets)
    if (offset < index_start || offset - index_start >= ci.message_index_length)
      throw_invalid_input(at + "points at a message index of channel " + std::to_string(channel) + " (at byte " +
                          std::to_string(offset) + ") outside the chunk's message index records");
}

// Spec "Schema": ids are unique, a Schema with id 0 is ignored; two with one id must agree.
void Reader::add_schema(const Schema& s, const Cursor& c, size_t pos) {
  if (s.id == 0) return;
  const auto [it, added] = schemas_.emplace(s.id, s);
  if (!added && (it->second.name != s.name || it->second.encoding != s.encoding))
    c.fail_at(pos, "schema " + std::to_string(s.id) + " is defined twice, as " + it->second.name + " and " + s.name);
}

// Spec "Channel": two Channel records with one id must agree. In Mode::Indexed (a chunk read
// through the summary) the summary must already list the channel.
void Reader::add_channel(const Channel& ch, const Cursor& c, size_t pos, Mode mode) {
  const auto it = channels_.find(ch.id);
  if (it == channels_.end()) {
    if (mode == Mode::Indexed)
      c.fail_at(pos, "channel " + std::to_string(ch.id) + " (" + ch.topic +
                         ") is not listed in the file's summary (an incomplete summary)");
    channels_.emplace(ch.id, ChannelInfo{ch, where(c.origin(), pos), kNoTopic});
    return;
  }
  const Channel& old = it->second.record;
  if (old.topic != ch.topic || old.schema_id != ch.schema_id || old.message_encoding != ch.message_encoding)
    c.fail_at(pos, "channel " + std::to_string(ch.id) + " is defined twice, differently (topic " + old.topic +
                       " and " + ch.topic + ")");
}

// Topics in the order of their lowest channel id; a topic's channels of two types make it one
// that cannot be indexed. Counts come from the Statistics (summed over channels) or a scan.
void Reader::assign_topics() {
  for (auto& [id, info] : channels_) {
    if (info.topic != kNoTopic) continue;
    std::string type;
    if (info.record.schema_id != 0) {
      const auto s = schemas_.find(info.record.schema_id);
      if (s == schemas_.end())
        throw_invalid_input(info.defined_at + "channel " + std::to_string(id) + " (" + info.record.topic +
                            ") refers to schema " + std::to_string(info.record.schema_id) +
                            ", which no Schema record defines");
      type = s->second.name;
    }
    uint32_t t = 0;
    while (t < topics_.size() && topics_[t].name != info.record.topic) ++t;
    if (t == topics_.size()) {
      topics_.push_back(TopicInfo{info.record.topic, type, stat_counts_.empty() ? -1 : 0, std::string()});
      topic_problem_.emplace_back();
    } else if (topics_[t].type != type && topic_problem_[t].empty()) {
      topic_problem_[t] = path_ + ": topic " + topics_[t].name + " has channels of two types, " + topics_[t].type +
                          " and " + type + "; planarvo reads a topic of one type";
    }
    info.topic = t;
    const auto n = stat_counts_.find(id);
    if (n != stat_counts_.end() && topics_[t].count >= 0)
      topics_[t].count += static_cast<int64_t>(std::min<uint64_t>(n->second, INT64_MAX - topics_[t].count));
  }
  if (scanned_) {
    for (TopicInfo& topic : topics_) topic.count = 0;
    for (const Found& f : all_) ++topics_[channels_.at(f.channel).topic].count;
  }
}

// A topic asked for: of one type, and ROS 2 CDR when it is one of the kinds planarvo decodes.
void Reader::check_asked(uint32_t topic) const {
  if (topic >= topics_.size())
    throw_invalid_argument(path_ + ": topic index " + std::to_string(topic) + " is not one of the file's " +
                           std::to_string(topics_.size()) + " topics");
  if (!topic_problem_[topic].empty()) throw_invalid_input(topic_problem_[topic]);
  if (message_kind(topics_[topic].type) == MessageKind::Other) return;
  for (const auto& [id, info] : channels_)
    if (info.topic == topic && info.record.message_encoding != "cdr")
      throw_invalid_input(path_ + ": topic " + topics_[topic].name + " (" + topics_[topic].type +
                          ") is encoded as \"" + info.record.message_encoding +
                          "\"; planarvo reads ROS 2 messages encoded as \"cdr\"");
}

void Reader::cancel_if_asked(const IndexProgress& progress, double fraction) const {
  if (progress && !progress(fraction)) throw Error(ErrorCode::Cancelled, path_ + ": indexing cancelled");
}

void Reader::read(const MessageRef& message, std::vector<uint8_t>& out) {
  if (message.location == kNoChunk) {  // a message outside chunks: straight from the file
    out.resize(message.size);
    read_exact(message.offset, message.size, out.data());
    return;
  }
  const auto it = chunks_.find(message.location);
  if (it == chunks_.end())
    throw_invalid_argument(path_ + ": a message reference that this file's index did not give (chunk at byte " +
                           std::to_string(message.location) + ")");
  const ChunkPlace& place = it->second;
  const uint64_t records_size = place.compression.empty() ? place.records_size : place.uncompressed_size;
  if (message.offset > records_size || message.size > records_size - message.offset)
    throw_invalid_argument(path_ + ": a message reference outside its chunk (at byte " +
                           std::to_string(message.location) + ")");
  // An uncompressed chunk without a CRC: straight from the file. With one, the whole chunk is
  // read (once, then kept while its messages are read) so that its CRC is checked on this path
  // too: a corrupt message read through the index went unnoticed (issue 27).
  if (place.compression.empty() && place.crc == 0) {
    out.resize(message.size);
    read_exact(place.records_offset + message.offset, message.size, out.data());
    return;
  }
  const std::vector<uint8_t>& records = chunk_records(message.location);
  out.assign(records.begin() + static_cast<std::ptrdiff_t>(message.offset),
             records.begin() + static_cast<std::ptrdiff_t>(message.offset + message.size));
}

}  // namespace mcap

std::unique_ptr<BagFile> open_mcap(const std::string& path) { return std::make_unique<mcap::Reader>(path); }

}  // namespace planarvo::io::bag
