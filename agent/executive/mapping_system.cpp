#include "marsala/agent/executive/mapping_system.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::agent::executive {
namespace {

std::string describe(const TerrainTile& t) {
  return "tile (" + std::to_string(t.tile_row) + ", " + std::to_string(t.tile_col) + ") of " + std::to_string(t.rows) +
         " x " + std::to_string(t.cols) + " cells";
}

}  // namespace

MappingSystem::MappingSystem(const GridGeometry& world, int tile_size) : heights_(world, 0.0), tile_size_(tile_size) {
  if (tile_size < 1) throw InvalidArgument("mapping system: tile size must be >= 1, got " + std::to_string(tile_size));
  known_ = CellMask::Zero(world.rows, world.cols);
}

void MappingSystem::integrate(const std::vector<TerrainTile>& tiles, Position pose) {
  for (const TerrainTile& tile : tiles) integrate_tile(tile);
  record_pose(pose);
}

std::string tile_problem(const TerrainTile& tile, const GridGeometry& world, int tile_size) {
  const long long row0 = static_cast<long long>(tile.tile_row) * tile_size;
  const long long col0 = static_cast<long long>(tile.tile_col) * tile_size;
  const bool placed = tile.tile_row >= 0 && tile.tile_col >= 0 && row0 < world.rows && col0 < world.cols;
  // A tile is tile_size x tile_size, cut short only by the grid edge.
  const bool sized = placed && tile.rows == std::min<long long>(tile_size, world.rows - row0) &&
                     tile.cols == std::min<long long>(tile_size, world.cols - col0);
  if (!sized)
    return describe(tile) + " does not fit the " + std::to_string(world.rows) + " x " + std::to_string(world.cols) +
           " grid in " + std::to_string(tile_size) + "-cell tiles";
  if (tile.heights.size() != static_cast<std::size_t>(tile.rows) * static_cast<std::size_t>(tile.cols))
    return describe(tile) + " carries " + std::to_string(tile.heights.size()) + " heights";
  for (double h : tile.heights)
    if (!std::isfinite(h) || std::abs(h) >= kMaxMagnitude) return describe(tile) + " has a non-finite or huge height";
  return {};
}

void MappingSystem::integrate_tile(const TerrainTile& tile) {
  const std::string problem = tile_problem(tile, heights_.geometry(), tile_size_);
  if (!problem.empty()) throw InvalidArgument("sensor frame: " + problem);
  const long long row0 = static_cast<long long>(tile.tile_row) * tile_size_;
  const long long col0 = static_cast<long long>(tile.tile_col) * tile_size_;
  for (int r = 0; r < tile.rows; ++r)
    for (int c = 0; c < tile.cols; ++c) {
      const int row = static_cast<int>(row0) + r + registration_.row, col = static_cast<int>(col0) + c + registration_.col;
      if (!heights_.contains({row, col})) continue;
      heights_(row, col) = tile.heights[static_cast<std::size_t>(r) * tile.cols + c];
      if (known_(row, col) == 0) {
        known_(row, col) = 1;
        ++known_count_;
      }
    }
}

void MappingSystem::record_pose(Position pose) {
  const auto cell = std::isfinite(pose.x) && std::isfinite(pose.y) ? heights_.cell_at(pose) : std::nullopt;
  if (!cell)
    throw InvalidArgument("mapping system: pose (" + std::to_string(pose.x) + ", " + std::to_string(pose.y) +
                          ") m is off the grid");
  if (trajectory_.empty() || trajectory_.back() != *cell) trajectory_.push_back(*cell);
}

}  // namespace marsala::agent::executive
