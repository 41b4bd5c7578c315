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
    throw IoError(
        fmt::format("scenario {}: terrain.file '{}' not found (looked for {})", s.source_path, s.terrain.file, path));
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
    throw InvalidArgument(fmt::format("scenario {}: terrain: {}", s.source_path, e.what()));
  }
  check_magnitudes(s, map);
  check_placement(s, map.geometry());
  return map;
}

void check_placement(const Scenario& s, const GridGeometry& g) {
  const Rect extent{g.xll_m, g.yll_m, g.xll_m + g.cols * g.cell_size_m, g.yll_m + g.rows * g.cell_size_m};
  const auto fail = [&](const std::string& field, const std::string& problem) {
    throw InvalidArgument(fmt::format("scenario {}: {}: {} (terrain {})", s.source_path, field, problem, extent));
  };
  // The off-terrain text keeps its unit-less "(x, y)": scenario tests and scripts look for it verbatim.
  const auto on_grid = [&](const std::string& field, Position p) {
    if (!g.cell_at(p)) fail(field, fmt::format("({}, {}) is off the terrain", p.x, p.y));
  };
  for (std::size_t i = 0; i < s.slots.size(); ++i) {
    const AgentSlot& slot = s.slots[i];
    const std::string field = fmt::format("agent[{}] (agent {})", i, slot.id);
    on_grid(field + ".start", slot.start);
    on_grid(field + ".target", slot.target);
  }
  on_grid("base", s.base.centre);
  const auto inside = [&](const std::string& field, const Rect& r) {
    if (r.x0 < extent.x0 || r.x1 > extent.x1 || r.y0 < extent.y0 || r.y1 > extent.y1)
      fail(field, fmt::format("{} is not inside the terrain", r));
  };
  switch (s.completion) {
    case CompletionKind::kAgentsAtGoal: inside("goal", s.goal.area); break;
    case CompletionKind::kPayloadPath:
      on_grid("payload_path.from", s.payload_path.from);
      on_grid("payload_path.to", s.payload_path.to);
      break;
    case CompletionKind::kLevelSite: inside("site", s.site.area); break;
  }
  if (s.has_goal_vector_map) inside("goal_vector_map", s.goal_vector_map.area);
}

}  // namespace marsala::scenario
