#include "marsala/runlog/run_log.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include <fmt/format.h>

#include "marsala/core/error.hpp"
#include "marsala/runlog/crc32c.hpp"

namespace marsala::runlog {
namespace {

void put_u32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFFu));
}

std::uint32_t get_u32(const char* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(static_cast<unsigned char>(p[i])) << (8 * i);
  return v;
}

std::string errno_text() { return std::strerror(errno); }

}  // namespace

RunLogWriter::RunLogWriter(int fd, std::string path, std::uint64_t bytes)
    : fd_(fd), path_(std::move(path)), bytes_(bytes) {}

RunLogWriter::RunLogWriter(RunLogWriter&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), path_(std::move(other.path_)), bytes_(other.bytes_) {}

RunLogWriter& RunLogWriter::operator=(RunLogWriter&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    bytes_ = other.bytes_;
  }
  return *this;
}

RunLogWriter::~RunLogWriter() {
  if (fd_ >= 0) ::close(fd_);
}

RunLogWriter RunLogWriter::create(const std::string& path, proto::LogHeader header) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError(fmt::format("{}: cannot create the run log: {}", path, errno_text()));
  RunLogWriter writer(fd, path, 0);
  writer.write_all(std::string(kMagic, kMagicBytes));
  writer.bytes_ = kMagicBytes;
  header.set_format_version(kFormatVersion);
  proto::LogRecord record;
  *record.mutable_header() = std::move(header);
  writer.append(record);
  return writer;
}

RunLogWriter RunLogWriter::continue_at(const std::string& path, std::uint64_t good_bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(fmt::format("{}: cannot open the run log to continue it: {}", path, errno_text()));
  RunLogWriter writer(fd, path, good_bytes);
  if (::ftruncate(fd, static_cast<off_t>(good_bytes)) != 0 || ::lseek(fd, static_cast<off_t>(good_bytes), SEEK_SET) < 0)
    throw IoError(fmt::format("{}: cannot cut the run log at byte {}: {}", path, good_bytes, errno_text()));
  return writer;
}

void RunLogWriter::write_all(const std::string& data) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd_, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = n < 0 ? errno_text() : "nothing written";
      // Leave the log ending at its last whole record, so that a reader never meets this torn one.
      if (::ftruncate(fd_, static_cast<off_t>(bytes_)) == 0) ::lseek(fd_, static_cast<off_t>(bytes_), SEEK_SET);
      throw IoError(fmt::format("{}: cannot append to the run log at byte {}: {}", path_, bytes_, why));
    }
    done += static_cast<std::size_t>(n);
  }
}

void RunLogWriter::append(const proto::LogRecord& record) {
  if (fd_ < 0) throw IoError(fmt::format("{}: the run log is closed", path_));
  std::string payload;
  if (!record.SerializeToString(&payload)) throw IoError(fmt::format("{}: cannot serialize a run-log record", path_));
  if (payload.size() > kMaxRecordBytes)
    throw IoError(fmt::format("{}: a run-log record of {} bytes exceeds the limit of {}", path_, payload.size(),
                              kMaxRecordBytes));
  frame_.clear();
  put_u32(frame_, static_cast<std::uint32_t>(payload.size()));
  put_u32(frame_, crc32c(payload.data(), payload.size()));
  frame_ += payload;
  write_all(frame_);
  bytes_ += frame_.size();
}

void RunLogWriter::sync() {
  if (fd_ >= 0 && ::fdatasync(fd_) != 0)
    throw IoError(fmt::format("{}: cannot sync the run log: {}", path_, errno_text()));
}

RunLogReader::RunLogReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
  if (!in_) throw IoError(fmt::format("{}: cannot open the run log", path));
  in_.seekg(0, std::ios::end);
  file_bytes_ = static_cast<std::uint64_t>(in_.tellg());
  in_.seekg(0);
  char magic[kMagicBytes];
  if (!in_.read(magic, kMagicBytes) || std::memcmp(magic, kMagic, kMagicBytes) != 0)
    throw ParseError(path, 0, fmt::format("not a run log: it does not start with \"{}\"", kMagic));
  offset_ = kMagicBytes;
  proto::LogRecord record;
  if (!read_record(record)) throw ParseError(path, 0, fmt::format("no intact header record: {}", tail_problem_));
  if (!record.has_header()) throw ParseError(path, 0, "the first record is not a header");
  header_ = record.header();
  if (header_.format_version() != kFormatVersion)
    throw ParseError(
        path, 0,
        fmt::format("format version {} is not the known version {}", header_.format_version(), kFormatVersion));
  first_record_ = offset_;
}

bool RunLogReader::read_record(proto::LogRecord& record) {
  tail_problem_.clear();
  if (offset_ == file_bytes_) return false;
  const std::uint64_t left = file_bytes_ - offset_;
  if (left < kFrameBytes) {
    tail_problem_ = fmt::format("{}: truncated record at byte {} ({} bytes, not even its frame)", path_, offset_, left);
    return false;
  }
  char frame[kFrameBytes];
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(offset_));
  if (!in_.read(frame, kFrameBytes)) {
    tail_problem_ = fmt::format("{}: cannot read the record at byte {}", path_, offset_);
    return false;
  }
  const std::uint32_t length = get_u32(frame);
  const std::uint32_t crc = get_u32(frame + 4);
  if (length > kMaxRecordBytes) {
    tail_problem_ = fmt::format("{}: damaged record at byte {}: length {} exceeds {} bytes", path_, offset_, length,
                                kMaxRecordBytes);
    return false;
  }
  if (left - kFrameBytes < length) {
    tail_problem_ = fmt::format("{}: truncated record at byte {} ({} of {} payload bytes)", path_, offset_,
                                left - kFrameBytes, length);
    return false;
  }
  payload_.resize(length);
  if (length > 0 && !in_.read(payload_.data(), length)) {
    tail_problem_ = fmt::format("{}: cannot read the record at byte {}", path_, offset_);
    return false;
  }
  if (crc32c(payload_.data(), payload_.size()) != crc) {
    tail_problem_ = fmt::format("{}: damaged record at byte {}: checksum mismatch", path_, offset_);
    return false;
  }
  if (!record.ParseFromString(payload_) || record.record_case() == proto::LogRecord::RECORD_NOT_SET) {
    tail_problem_ =
        fmt::format("{}: damaged record at byte {}: its checksum holds but it is not a record", path_, offset_);
    return false;
  }
  offset_ += kFrameBytes + length;
  return true;
}

bool RunLogReader::next(proto::LogRecord& record) {
  const std::uint64_t start = offset_;
  if (!read_record(record)) {
    if (!tail_problem_.empty())
      tail_problem_ += fmt::format("; {} bytes after the last good record", file_bytes_ - offset_);
    return false;
  }
  if (record.has_header()) {
    offset_ = start;
    tail_problem_ = fmt::format("{}: a second header at byte {}; {} bytes after the last good record", path_, offset_,
                                file_bytes_ - offset_);
    return false;
  }
  return true;
}

void RunLogReader::seek(std::uint64_t offset) {
  if (offset < first_record_ || offset > file_bytes_)
    throw InvalidArgument(fmt::format("{}: cannot continue reading at byte {}: its records lie between bytes {} and {}",
                                      path_, offset, first_record_, file_bytes_));
  offset_ = offset;
  tail_problem_.clear();
}

}  // namespace marsala::runlog
