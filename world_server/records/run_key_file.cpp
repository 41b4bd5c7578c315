#include "marsala/world_server/records/run_key_file.hpp"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <system_error>

namespace marsala::world_server {

std::string run_key_path(const std::string& dir) { return (std::filesystem::path(dir) / "run.key").string(); }

protocol::RunKey settle_run_key(const std::string& given, const std::string& dir, bool resumed) {
  const std::string kept = run_key_path(dir);
  if (!given.empty()) {
    const protocol::RunKey key = protocol::load_run_key(given);
    if (!resumed) protocol::save_run_key(key, kept);
    return key;
  }
  if (resumed) {
    std::error_code ec;
    if (std::filesystem::exists(kept, ec)) return protocol::load_run_key(kept);
    spdlog::warn("{} is missing: this world proves itself with a new key, which agents and monitors that pinned the "
                 "run's first world do not believe",
                 kept);
    return protocol::make_run_key();
  }
  const protocol::RunKey key = protocol::make_run_key();
  protocol::save_run_key(key, kept);
  return key;
}

}  // namespace marsala::world_server
