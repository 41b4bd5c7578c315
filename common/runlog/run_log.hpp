#pragma once
// run.log, the world's append-only record of a run (idl/run_log.proto, docs/runtime.md#persistence): the magic
// "MARSLOG1", then records framed as [uint32 LE length][uint32 LE CRC-32C of the payload][payload: one LogRecord],
// the first of them a header. A crash can leave a torn record at the tail; the reader stops at the first record that
// is short, too long or fails its checksum, and says where and why, so that nothing damaged is ever applied.

#include <cstdint>
#include <fstream>
#include <string>

#include "idl/run_log.pb.h"

namespace marsala::runlog {

/// The log's name in a run's output folder.
inline constexpr const char* kRunLogFile = "run.log";
/// The file's first eight bytes.
inline constexpr char kMagic[] = "MARSLOG1";
inline constexpr std::uint64_t kMagicBytes = 8;
/// Bytes before each payload: length and checksum.
inline constexpr std::uint64_t kFrameBytes = 8;
/// The longest payload a reader accepts; a longer length field is damage [bytes].
inline constexpr std::uint32_t kMaxRecordBytes = 64u << 20;
/// The header's format_version this code writes and reads.
inline constexpr std::uint32_t kFormatVersion = 1;

/// Appends records to a run log. Each append is one write(2) of the whole framed record: when append() returns the
/// record is in the operating system's hands and survives a crash of this process; sync() makes everything written
/// durable against a crash of the machine.
class RunLogWriter {
 public:
  /// Creates `path`, which must not exist, and writes the magic and `header` (format_version set to
  /// kFormatVersion). Throws IoError.
  static RunLogWriter create(const std::string& path, proto::LogHeader header);
  /// Continues an existing log after its last good record, which ends at byte `good_bytes` (RunLogReader::offset()
  /// after its last record): anything after it is cut. Throws IoError.
  static RunLogWriter continue_at(const std::string& path, std::uint64_t good_bytes);

  RunLogWriter(RunLogWriter&& other) noexcept;
  RunLogWriter& operator=(RunLogWriter&& other) noexcept;
  RunLogWriter(const RunLogWriter&) = delete;
  RunLogWriter& operator=(const RunLogWriter&) = delete;
  ~RunLogWriter();

  /// Appends one record; throws IoError (disk full, closed file), after which the log ends at its last whole record
  /// (a partial write is cut off again).
  void append(const proto::LogRecord& record);
  /// fdatasync(2); throws IoError.
  void sync();
  /// The log's size: the byte offset just after the last record [bytes].
  std::uint64_t bytes() const { return bytes_; }
  const std::string& path() const { return path_; }

 private:
  RunLogWriter(int fd, std::string path, std::uint64_t bytes);
  void write_all(const std::string& data);

  int fd_ = -1;
  std::string path_;
  std::uint64_t bytes_ = 0;
  std::string frame_;  ///< reused buffer of one framed record
};

/// Reads a run log record by record.
class RunLogReader {
 public:
  /// Opens `path` and reads its header. Throws IoError when it cannot be opened, ParseError when it does not start
  /// with the magic and an intact header record of a known format version.
  explicit RunLogReader(const std::string& path);

  const proto::LogHeader& header() const { return header_; }
  /// Reads the next record; false at the end of the good records: the file's clean end, or a damaged tail
  /// (tail_problem() says which and where).
  bool next(proto::LogRecord& record);
  /// Continues reading at byte `offset`, a record boundary (e.g. a snapshot's log_offset; a wrong one fails the next
  /// record's checksum). Throws InvalidArgument when it lies before the first record or beyond the file.
  void seek(std::uint64_t offset);
  /// The byte offset just after the last record read.
  std::uint64_t offset() const { return offset_; }
  /// The byte offset just after the header record.
  std::uint64_t first_record_offset() const { return first_record_; }
  /// The file's size [bytes].
  std::uint64_t file_bytes() const { return file_bytes_; }
  /// After next() returned false: empty when the log ended at a record boundary; else what is wrong, e.g.
  /// "run.log: truncated record at byte 1234 (28 of 40 bytes)", with the bytes after the last good record.
  const std::string& tail_problem() const { return tail_problem_; }
  /// Bytes after the last good record that were not read (0 for a clean end).
  std::uint64_t damaged_bytes() const { return file_bytes_ - offset_; }

 private:
  bool read_record(proto::LogRecord& record);

  std::string path_;
  std::ifstream in_;
  proto::LogHeader header_;
  std::uint64_t offset_ = 0;
  std::uint64_t first_record_ = 0;
  std::uint64_t file_bytes_ = 0;
  std::string tail_problem_;
  std::string payload_;
};

}  // namespace marsala::runlog
