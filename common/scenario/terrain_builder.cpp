#include "marsala/scenario/terrain_builder.hpp"

#include <cctype>
#include <cstdio>
#include <filesystem>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/terrain/asc_io.hpp"
#include "marsala/terrain/generators.hpp"
#include "marsala/terrain/geotiff_import.hpp"
#include "marsala/terrain/resample.hpp"

namespace marsala::scenario {
namespace {

namespace fs = std::filesystem;

bool is_tiff(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".tif" || ext == ".tiff";
}

Heightmap read_terrain_file(const Scenario& s) {
  const std::string path = resolve_terrain_path(s);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw IoError("scenario " + s.source_path + ": terrain.file '" + s.terrain.file + "' not found (looked for " +
                  path + ")");
  Heightmap map = is_tiff(path) ? terrain::read_geotiff(path) : terrain::read_asc(path);
  const TerrainSource& t = s.terrain;
  if (t.has_crop) map = terrain::crop(map, t.crop_x0_m, t.crop_y0_m, t.crop_width_m, t.crop_height_m);
  if (t.resample_cell_size_m > 0.0) map = terrain::resample_bilinear(map, t.resample_cell_size_m);
  if (t.zero_base) map.heights().array() -= map.min_height();
  return map;
}

/// A world's cells and heights stay within what every processor computes in doubles
/// (docs/runtime.md#scenario-validation).
void check_magnitudes(const Scenario& s, const Heightmap& map) {
  const double cs = map.cell_size_m();
  if (!(cs >= kMinCellSizeM && cs <= kMaxMagnitude))
    throw InvalidArgument(fmt::format("scenario {}: terrain: cell size {} m is outside [{}, {}] m", s.source_path, cs,
                                      kMinCellSizeM, kMaxMagnitude));
  const double highest = std::max(std::abs(map.min_height()), std::abs(map.max_height()));
  if (!(highest <= kMaxMagnitude))
    throw InvalidArgument(
        fmt::format("scenario {}: terrain: a height of {} m is beyond +-{} m", s.source_path, highest, kMaxMagnitude));
}

}  // namespace

std::string resolve_terrain_path(const Scenario& s) {
  const fs::path file(s.terrain.file);
  if (file.is_absolute()) return file.string();
  return (fs::path(s.source_path).parent_path() / file).lexically_normal().string();
}

Heightmap build_terrain(const Scenario& s) {
  Heightmap map;
  try {
    if (!s.terrain.file.empty()) {
      map = read_terrain_file(s);
    } else {
      terrain::GeneratorSpec spec;
      spec.rows = s.terrain.rows;
      spec.cols = s.terrain.cols;
      spec.cell_size_m = s.terrain.cell_size_m;
      spec.seed = s.terrain.seed;
      spec.params = s.terrain.params;
      map = terrain::generate_terrain(s.terrain.method, spec);
    }
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("scenario " + s.source_path + ": terrain: " + e.what());
  }
  check_magnitudes(s, map);
  check_placement(s, map.geometry());
  return map;
}

void check_placement(const Scenario& s, const GridGeometry& g) {
  const double x1 = g.xll_m + g.cols * g.cell_size_m;
  const double y1 = g.yll_m + g.rows * g.cell_size_m;
  const std::string extent = "[" + fmt::format("{}", g.xll_m) + ", " + fmt::format("{}", x1) + "] x [" +
                             fmt::format("{}", g.yll_m) + ", " + fmt::format("{}", y1) + "] m";
  const auto fail = [&](const std::string& field, const std::string& problem) {
    throw InvalidArgument("scenario " + s.source_path + ": " + field + ": " + problem + " (terrain " + extent + ")");
  };
  const auto on_grid = [&](const std::string& field, double x, double y) {
    if (!g.cell_at({x, y}))
      fail(field, "(" + fmt::format("{}", x) + ", " + fmt::format("{}", y) + ") is off the terrain");
  };
  for (std::size_t i = 0; i < s.slots.size(); ++i) {
    const AgentSlot& slot = s.slots[i];
    const std::string field = "agent[" + std::to_string(i) + "] (agent " + std::to_string(slot.id) + ")";
    on_grid(field + ".start", slot.start.x, slot.start.y);
    on_grid(field + ".target", slot.target.x, slot.target.y);
  }
  on_grid("base", s.base.centre.x, s.base.centre.y);
  const auto inside = [&](const std::string& field, double x0, double y0, double xa, double ya) {
    if (x0 < g.xll_m || xa > x1 || y0 < g.yll_m || ya > y1)
      fail(field, "[" + fmt::format("{}", x0) + ", " + fmt::format("{}", xa) + "] x [" + fmt::format("{}", y0) + ", " +
                      fmt::format("{}", ya) + "] m is not inside the terrain");
  };
  switch (s.completion) {
    case CompletionKind::kAgentsAtGoal: inside("goal", s.goal.area.x0, s.goal.area.y0, s.goal.area.x1, s.goal.area.y1); break;
    case CompletionKind::kPayloadPath:
      on_grid("payload_path.from", s.payload_path.from.x, s.payload_path.from.y);
      on_grid("payload_path.to", s.payload_path.to.x, s.payload_path.to.y);
      break;
    case CompletionKind::kLevelSite: inside("site", s.site.area.x0, s.site.area.y0, s.site.area.x1, s.site.area.y1); break;
  }
  if (s.has_goal_vector_map) {
    const GoalVectorMapSpec& m = s.goal_vector_map;
    inside("goal_vector_map", m.area.x0, m.area.y0, m.area.x1, m.area.y1);
  }
}

}  // namespace marsala::scenario
