#include "marsala/monitor/mcap_writer.hpp"

#include <fmt/format.h>

#include "marsala/core/error.hpp"
#include "marsala/runlog/crc32c.hpp"

namespace marsala::monitor {
namespace {

using runlog::crc32_iso;

constexpr char kMagic[] = "\x89MCAP0\r\n";
constexpr std::size_t kMagicBytes = 8;

// Opcodes (https://mcap.dev/spec#records).
enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// Little-endian primitives, as the spec writes every integer.
template <typename T>
void put(std::string& s, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i) s.push_back(static_cast<char>((static_cast<std::uint64_t>(v) >> (8 * i)) & 0xFFu));
}

/// A String or 4-byte-length Bytes field.
void put_string(std::string& s, const std::string& v) {
  put<std::uint32_t>(s, static_cast<std::uint32_t>(v.size()));
  s += v;
}

/// opcode, uint64 length, content.
std::string record(Op op, const std::string& content) {
  std::string r;
  r.reserve(content.size() + 9);
  put<std::uint8_t>(r, op);
  put<std::uint64_t>(r, content.size());
  r += content;
  return r;
}

}  // namespace

McapWriter::McapWriter(std::ostream& out, const std::string& library, std::uint64_t chunk_bytes)
    : out_(out), chunk_bytes_(chunk_bytes) {
  std::string header;
  put_string(header, "");  // profile: none of the well-known ones
  put_string(header, library);
  write_data(std::string(kMagic, kMagicBytes) + record(kHeader, header));
}

void McapWriter::write_data(const std::string& bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  data_crc_ = crc32_iso(bytes.data(), bytes.size(), data_crc_);
  offset_ += bytes.size();
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  const auto id = static_cast<std::uint16_t>(stats_.schemas + 1);
  std::string c;
  put<std::uint16_t>(c, id);
  put_string(c, name);
  put_string(c, encoding);
  put_string(c, data);
  const std::string r = record(kSchema, c);
  schema_records_ += r;
  write_data(r);
  stats_.schemas = id;
  return id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding) {
  if (schema_id == 0 || schema_id > stats_.schemas)
    throw InvalidArgument(fmt::format("MCAP channel {}: no schema {}", topic, schema_id));
  const auto id = static_cast<std::uint16_t>(stats_.channels);
  std::string c;
  put<std::uint16_t>(c, id);
  put<std::uint16_t>(c, schema_id);
  put_string(c, topic);
  put_string(c, message_encoding);
  put<std::uint32_t>(c, 0);  // metadata: an empty map
  const std::string r = record(kChannel, c);
  channel_records_ += r;
  write_data(r);
  ++stats_.channels;
  sequence_.push_back(0);
  stats_.per_channel[id] = 0;
  return id;
}

void McapWriter::write_message(std::uint16_t channel, std::uint64_t time_ns, const std::string& data) {
  if (finished_) throw InvalidArgument("MCAP writer: a message after finish()");
  if (channel >= stats_.channels) throw InvalidArgument(fmt::format("MCAP message: no channel {}", channel));
  std::string c;
  put<std::uint16_t>(c, channel);
  put<std::uint32_t>(c, sequence_[channel]++);
  put<std::uint64_t>(c, time_ns);  // log time
  put<std::uint64_t>(c, time_ns);  // publish time
  c += data;
  if (chunk_.empty() || time_ns < chunk_start_ns_) chunk_start_ns_ = time_ns;
  if (chunk_.empty() || time_ns > chunk_end_ns_) chunk_end_ns_ = time_ns;
  if (stats_.messages == 0 || time_ns < stats_.start_ns) stats_.start_ns = time_ns;
  if (stats_.messages == 0 || time_ns > stats_.end_ns) stats_.end_ns = time_ns;
  chunk_index_[channel].emplace_back(time_ns, chunk_.size());
  chunk_ += record(kMessage, c);
  ++stats_.messages;
  ++stats_.per_channel[channel];
  if (chunk_.size() >= chunk_bytes_) flush_chunk();
}

void McapWriter::flush_chunk() {
  if (chunk_.empty()) return;
  const std::uint64_t chunk_start = offset_;
  std::string c;
  put<std::uint64_t>(c, chunk_start_ns_);
  put<std::uint64_t>(c, chunk_end_ns_);
  put<std::uint64_t>(c, chunk_.size());  // uncompressed size
  put<std::uint32_t>(c, crc32_iso(chunk_.data(), chunk_.size()));
  put_string(c, "");  // no compression
  put<std::uint64_t>(c, chunk_.size());
  c += chunk_;
  write_data(record(kChunk, c));
  const std::uint64_t chunk_length = offset_ - chunk_start;

  // One MessageIndex per channel with messages in the chunk, in channel order (std::map), right after the chunk.
  std::string offsets;  // the ChunkIndex's map: channel -> offset of its MessageIndex
  const std::uint64_t indexes_start = offset_;
  for (const auto& [channel, entries] : chunk_index_) {
    std::string m;
    put<std::uint16_t>(m, channel);
    put<std::uint32_t>(m, static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [time_ns, at] : entries) {
      put<std::uint64_t>(m, time_ns);
      put<std::uint64_t>(m, at);
    }
    put<std::uint16_t>(offsets, channel);
    put<std::uint64_t>(offsets, offset_);
    write_data(record(kMessageIndex, m));
  }
  std::string ci;
  put<std::uint64_t>(ci, chunk_start_ns_);
  put<std::uint64_t>(ci, chunk_end_ns_);
  put<std::uint64_t>(ci, chunk_start);
  put<std::uint64_t>(ci, chunk_length);
  put_string(ci, offsets);
  put<std::uint64_t>(ci, offset_ - indexes_start);
  put_string(ci, "");
  put<std::uint64_t>(ci, chunk_.size());  // compressed size: stored as is
  put<std::uint64_t>(ci, chunk_.size());
  chunk_index_records_ += record(kChunkIndex, ci);
  ++stats_.chunks;
  chunk_.clear();
  chunk_index_.clear();
}

void McapWriter::finish() {
  if (finished_) return;
  flush_chunk();
  finished_ = true;
  std::string data_end;
  put<std::uint32_t>(data_end, data_crc_);
  write_data(record(kDataEnd, data_end));

  const std::uint64_t summary_start = offset_;
  std::string stats;
  put<std::uint64_t>(stats, stats_.messages);
  put<std::uint16_t>(stats, stats_.schemas);
  put<std::uint32_t>(stats, stats_.channels);
  put<std::uint32_t>(stats, 0);  // attachments
  put<std::uint32_t>(stats, 0);  // metadata
  put<std::uint32_t>(stats, stats_.chunks);
  put<std::uint64_t>(stats, stats_.start_ns);
  put<std::uint64_t>(stats, stats_.end_ns);
  std::string counts;
  for (const auto& [channel, n] : stats_.per_channel) {
    put<std::uint16_t>(counts, channel);
    put<std::uint64_t>(counts, n);
  }
  put_string(stats, counts);

  // The summary's groups, each found again through a SummaryOffset record.
  std::string summary;
  std::string summary_offsets;
  const auto group = [&](Op op, const std::string& records) {
    if (records.empty()) return;
    std::string so;
    put<std::uint8_t>(so, op);
    put<std::uint64_t>(so, summary_start + summary.size());
    put<std::uint64_t>(so, records.size());
    summary_offsets += record(kSummaryOffset, so);
    summary += records;
  };
  group(kSchema, schema_records_);
  group(kChannel, channel_records_);
  group(kStatistics, record(kStatistics, stats));
  group(kChunkIndex, chunk_index_records_);
  const std::uint64_t summary_offset_start = summary_start + summary.size();

  std::string tail = summary + summary_offsets;
  put<std::uint8_t>(tail, kFooter);
  put<std::uint64_t>(tail, 20);  // footer content: two uint64 and the CRC
  put<std::uint64_t>(tail, summary_start);
  put<std::uint64_t>(tail, summary_offset_start);
  put<std::uint32_t>(tail, crc32_iso(tail.data(), tail.size()));
  tail.append(kMagic, kMagicBytes);
  out_.write(tail.data(), static_cast<std::streamsize>(tail.size()));
  offset_ += tail.size();
  out_.flush();
  if (!out_) throw IoError("MCAP writer: the output stream failed (disk full?)");
}

}  // namespace marsala::monitor
