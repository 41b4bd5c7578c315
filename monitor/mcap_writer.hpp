#pragma once
// A small MCAP writer (https://mcap.dev/spec, version 0): magic, Header, the Schema and Channel records, the messages
// in uncompressed Chunks each followed by its MessageIndex records, DataEnd with the data section's CRC-32, then a
// Summary section (Schema and Channel records again, Statistics, ChunkIndex records) with its SummaryOffset records,
// the Footer and the closing magic, so that indexed readers seek and stream readers read straight through. No
// compression, no attachments, no metadata; checksums by runlog::crc32_iso. Writes to an ostream only: the caller
// opens, names and renames the file.

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace marsala::monitor {

/// What an MCAP file holds, as its Statistics record says.
struct McapStatistics {
  std::uint64_t messages = 0;
  std::uint16_t schemas = 0;
  std::uint32_t channels = 0;
  std::uint32_t chunks = 0;
  std::uint64_t start_ns = 0;  ///< earliest log time [ns]
  std::uint64_t end_ns = 0;    ///< latest log time [ns]
  std::map<std::uint16_t, std::uint64_t> per_channel;  ///< messages per channel id
};

/// Writes one MCAP file to a stream: the constructor writes the magic and the Header, finish() everything after the
/// last message. Schemas and channels must be added before the messages that use them.
class McapWriter {
 public:
  /// Starts the file on `out` (which must outlive the writer); `library` goes into the Header. A chunk is closed once
  /// its records reach `chunk_bytes` [bytes].
  McapWriter(std::ostream& out, const std::string& library, std::uint64_t chunk_bytes = 1u << 20);

  /// Adds a schema (name e.g. "foxglove.Grid", encoding e.g. "jsonschema", its text); returns its id (from 1).
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  /// Adds a channel on `topic` with messages in `message_encoding` (e.g. "json") of schema `schema_id`; returns
  /// its id (from 0). Throws InvalidArgument for an unknown schema id.
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding);
  /// Writes a message on `channel` logged and published at `time_ns` [ns since the epoch]. Log times need not
  /// increase. Throws InvalidArgument for an unknown channel or after finish().
  void write_message(std::uint16_t channel, std::uint64_t time_ns, const std::string& data);
  /// Closes the last chunk and writes DataEnd, the summary, the footer and the closing magic. Throws IoError when
  /// the stream failed at any point.
  void finish();

  const McapStatistics& statistics() const { return stats_; }
  /// Bytes written so far.
  std::uint64_t bytes() const { return offset_; }

 private:
  void write_data(const std::string& bytes);
  void flush_chunk();

  std::ostream& out_;
  std::uint64_t chunk_bytes_;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  bool finished_ = false;
  std::string schema_records_;   ///< the Schema records, repeated in the summary
  std::string channel_records_;  ///< the Channel records, repeated in the summary
  std::vector<std::uint32_t> sequence_;  ///< next sequence number per channel
  std::string chunk_;                    ///< records of the open chunk
  std::uint64_t chunk_start_ns_ = 0;
  std::uint64_t chunk_end_ns_ = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;  ///< (time, offset)
  std::string chunk_index_records_;  ///< the ChunkIndex records, for the summary
  McapStatistics stats_;
};

}  // namespace marsala::monitor
