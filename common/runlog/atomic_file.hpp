#pragma once
// Files that appear whole or not at all: written under "<path>.tmp", then renamed over the final name, so that a
// reader, a crash or a full disk never leaves a half-written file under it (docs/runtime.md#outputs).

#include <filesystem>
#include <string>
#include <system_error>

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala::runlog {

/// Calls write(tmp) with tmp = "<path>.tmp", then renames tmp over `path`. Whatever write() throws, and IoError when
/// the rename fails; the temporary is removed either way.
template <typename Write>
void write_atomically(const std::string& path, Write&& write) {
  namespace fs = std::filesystem;
  const std::string tmp = path + ".tmp";
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw IoError(fmt::format("cannot rename '{}' to '{}': {}", tmp, path, ec.message()));
  }
}

}  // namespace marsala::runlog
