#include "marsala/agent/runtime/map_dump.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <sstream>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "marsala/agent/runtime/agent_runtime.hpp"
#include "marsala/core/error.hpp"
#include "marsala/runlog/atomic_file.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace marsala::agent::runtime {
namespace {

namespace fs = std::filesystem;

/// The records of a folder, "agent-<id>-map.json", in name order.
std::vector<fs::path> records_in(const std::string& dir) {
  static const std::regex kRecord("agent-[0-9]+-map\\.json");
  std::vector<fs::path> found;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec))
    if (std::regex_match(e.path().filename().string(), kRecord)) found.push_back(e.path());
  if (ec) throw IoError(fmt::format("--dump-map {}: cannot list it: {}", dir, ec.message()));
  std::sort(found.begin(), found.end());
  return found;
}

/// The believed heights: the map's where known, NaN (written as NODATA) elsewhere.
Heightmap believed_heights(const deliberative::KnownMap& map) {
  Heightmap out(map.geometry(), std::numeric_limits<double>::quiet_NaN());
  for (int r = 0; r < out.rows(); ++r)
    for (int c = 0; c < out.cols(); ++c)
      if (map.known(r, c) != 0) out(r, c) = map.heights(r, c);
  return out;
}

nlohmann::ordered_json record_json(const deliberative::KnownMap& map, const MapDumpInfo& info,
                                   const std::string& height_file) {
  const GridGeometry& g = map.geometry();
  long long known = 0, assumed = 0;
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c)
      if (map.known(r, c) != 0) {
        ++known;
        assumed += map.assumed(r, c) != 0 ? 1 : 0;
      }
  return {{"run_id", info.run_id},
          {"agent_id", info.agent_id},
          {"name", info.name},
          {"step", info.step},
          {"end", info.end},
          {"rows", g.rows},
          {"cols", g.cols},
          {"cell_size_m", g.cell_size_m},
          {"xll_m", g.xll_m},
          {"yll_m", g.yll_m},
          {"cells", static_cast<long long>(g.rows) * g.cols},
          {"known_cells", known},
          {"assumed_cells", assumed},
          {"sensor", info.sensor},
          {"scanned", map.scanned},
          {"height_file", height_file}};
}

}  // namespace

MapRecord read_map_record(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("cannot read '{}'", path));
  std::ostringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    MapRecord r;
    r.run_id = j.at("run_id").get<std::string>();
    r.agent_id = j.at("agent_id").get<std::uint32_t>();
    r.step = j.at("step").get<std::uint64_t>();
    r.known_cells = j.at("known_cells").get<long long>();
    r.height_file = j.at("height_file").get<std::string>();
    return r;
  } catch (const nlohmann::json::exception& e) {
    throw ParseError(path, 0, fmt::format("not a map record (agent-<id>-map.json): {}", e.what()));
  }
}

MapDump::MapDump(std::string dir) : dir_(std::move(dir)) {
  if (dir_.empty()) throw InvalidArgument("--dump-map: the folder name is empty");
  std::error_code ec;
  if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec))
    throw InvalidArgument(fmt::format("--dump-map {}: not a folder", dir_));
  fs::create_directories(dir_, ec);
  if (ec) throw InvalidArgument(fmt::format("--dump-map {}: cannot create it: {}", dir_, ec.message()));
  if (::access(dir_.c_str(), W_OK | X_OK) != 0) throw InvalidArgument(fmt::format("--dump-map {}: not writable", dir_));
  for (const fs::path& p : records_in(dir_)) (void)read_map_record(p.string());
}

std::string MapDump::problem_for_run(const std::string& run_id) const {
  for (const fs::path& p : records_in(dir_)) {
    const MapRecord r = read_map_record(p.string());
    if (r.run_id != run_id)
      return fmt::format("--dump-map: {} holds a map of run '{}', not of this run '{}': give a fresh folder",
                         p.string(), r.run_id, run_id);
  }
  return {};
}

std::string MapDump::height_path(std::uint32_t agent_id) const {
  return (fs::path(dir_) / fmt::format("agent-{}-height.asc", agent_id)).string();
}

std::string MapDump::record_path(std::uint32_t agent_id) const {
  return (fs::path(dir_) / fmt::format("agent-{}-map.json", agent_id)).string();
}

void MapDump::write(const deliberative::KnownMap& map, const MapDumpInfo& info) const {
  const std::string height = height_path(info.agent_id);
  runlog::write_atomically(height, [&](const std::string& tmp) { terrain::write_asc(believed_heights(map), tmp); });
  const std::string record = record_path(info.agent_id);
  const std::string text = record_json(map, info, fs::path(height).filename().string()).dump(2) + "\n";
  runlog::write_atomically(record, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) throw IoError(fmt::format("cannot write '{}'", tmp));
  });
}

void dump_maps_into(std::shared_ptr<const MapDump> dump, RuntimeConfig& config) {
  config.on_admitted = [dump](const std::string& run_id) { return dump->problem_for_run(run_id); };
  config.on_end = [dump](const AgentRuntime& agent, const RunResult& result, bool failed) {
    const RuntimeConfig& c = agent.config();
    const std::optional<deliberative::KnownMap> map = agent.behaviour().known_map();
    if (!map) {
      spdlog::info("agent {}: --dump-map: its behaviour keeps no map; nothing written", c.agent_id);
      return;
    }
    const MapDumpInfo info{result.run_id,
                           c.agent_id,
                           c.name,
                           result.last_step,
                           failed ? std::string("error") : to_string(result.outcome),
                           to_string(c.type.sensor.kind)};
    dump->write(*map, info);
    spdlog::info("agent {}: map of step {} written to {}", c.agent_id, result.last_step, dump->height_path(c.agent_id));
  };
}

}  // namespace marsala::agent::runtime
