#include "marsala/world_server/records/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace marsala::world_server {
namespace fs = std::filesystem;

namespace {

/// The pid the lock file names, as written by its holder ("unknown" while it has not written it yet).
std::string holder_pid(const fs::path& file) {
  std::ifstream in(file);
  std::string pid;
  in >> pid;
  return pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos ? std::string("unknown") : pid;
}

}  // namespace

OutputLock::OutputLock(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(fmt::format("cannot create output folder '{}': {}", dir, ec.message()));
  const fs::path file = fs::path(dir) / kOutputLockFile;
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw IoError(fmt::format("cannot open '{}': {}", file.string(), std::strerror(errno)));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    if (error != EWOULDBLOCK) throw IoError(fmt::format("cannot lock '{}': {}", file.string(), std::strerror(error)));
    throw FolderInUse(fmt::format(
        "output folder '{}' is in use by marsala-world pid {} (it holds {}): a run goes on there, or is paused; "
        "wait for its end, stop it, or give another --out",
        dir, holder_pid(file), kOutputLockFile));
  }
  // The holder's pid, for the message of whoever is refused; the lock itself needs no content.
  const std::string pid = fmt::format("{}\n", ::getpid());
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
    const int error = errno;
    ::close(fd_);
    fd_ = -1;
    throw IoError(fmt::format("cannot write '{}': {}", file.string(), std::strerror(error)));
  }
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace marsala::world_server
