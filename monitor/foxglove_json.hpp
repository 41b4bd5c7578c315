#pragma once
// The messages of an MCAP export (docs/runtime.md#mcap-export) in Foxglove's JSON encoding: foxglove.Grid for the
// terrain, foxglove.SceneUpdate for the robots, foxglove.Log for the world's events; and the JSON Schemas embedded in
// the file for each, written from Foxglove's public schema definitions (only the fields written here, each of them
// required). Pure functions: data in, JSON text out.

#include <cstdint>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"

namespace marsala::monitor {

/// Name and JSON Schema text of the three schemas.
struct JsonSchema {
  std::string name;  ///< e.g. "foxglove.Grid"
  std::string text;  ///< the JSON Schema
};
JsonSchema grid_schema();
JsonSchema scene_update_schema();
JsonSchema log_schema();

/// The frame every message is in: the world's (x east, y north, z up) [m].
inline constexpr const char* kWorldFrame = "world";

/// A foxglove.Grid of `terrain` at `time_ns` [ns]: one float32 field "height" [m], grid row i = the terrain's row
/// rows - 1 - i (foxglove rows run along +y, the terrain's first row is its northmost), the grid's corner at the
/// terrain's lower-left corner (xll, yll, 0), cells cell_size_m square, data in base64.
std::string grid_message(const Heightmap& terrain, std::uint64_t time_ns);

/// One robot as the export shows it.
struct RobotPose {
  std::uint32_t id = 0;
  std::string name;
  Position position;         ///< [m]
  double z_m = 0.0;          ///< height of the cell under it [m]
  double heading_rad = 0.0;  ///< [rad from east, counter-clockwise]
  double body_diameter_m = 1.0;  ///< its body's delta [m]
  std::string state;         ///< its behaviour's state in its latest request
  double material_m3 = 0.0;  ///< on board [m^3]
  double deposited_m3 = 0.0; ///< placed so far [m^3]
  bool dropped = false;
};

/// A foxglove.SceneUpdate at `time_ns` [ns] with one entity per robot ("agent-<id>"): a cylinder of its body
/// standing on the terrain, an arrow along its heading and a text label, and metadata agent_id, name, x_m, y_m, z_m,
/// heading_rad, state, material_m3, deposited_m3, dropped (numbers as the shortest text that reads back exactly).
std::string scene_update_message(const std::vector<RobotPose>& robots, std::uint64_t time_ns);

/// Levels of foxglove.Log.
enum class LogLevel : int { kInfo = 2, kWarning = 3, kError = 4 };

/// A foxglove.Log at `time_ns` [ns] from `name` (e.g. "agent-2" or "world").
std::string log_message(std::uint64_t time_ns, LogLevel level, const std::string& name, const std::string& text);

/// `bytes` in standard base64 with padding.
std::string base64(const std::string& bytes);

}  // namespace marsala::monitor
