#pragma once
// Run folders are owned (docs/runtime.md#run-folders): a world holds an exclusive lock on its output folder for as long
// as it runs, paused included. The lock is flock(2) on DIR/world.lock, which holds the holder's pid for the message of
// whoever is refused; the kernel releases it when the process ends, however it ends (a SIGKILL leaves nothing to
// clean).

#include <string>

#include "marsala/core/error.hpp"

namespace marsala::world_server {

/// The lock file of an output folder.
inline constexpr const char* kOutputLockFile = "world.lock";

/// Another process holds the output folder (a run goes on there, or is paused).
class FolderInUse : public IoError {
 public:
  explicit FolderInUse(const std::string& what) : IoError(what) {}
};

/// The exclusive lock of one output folder, held from construction to destruction.
class OutputLock {
 public:
  /// Creates `dir` when missing and locks it, writing this process's pid into the lock file. Throws FolderInUse naming
  /// the holder's pid when another open lock holds it (another process, or another OutputLock of this one), IoError
  /// when the folder or the lock file cannot be made.
  explicit OutputLock(const std::string& dir);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace marsala::world_server
