#pragma once
// The frames multi-process bus tests send: contents derived from the step alone, so writer and reader processes
// agree on them without talking. Heights are arbitrary 64-bit patterns (NaN payloads, -0.0, subnormals) so that a
// frame compares equal only if it travelled bit for bit.

#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "marsala/protocol/messages.hpp"

namespace marsala::probe {
using namespace marsala::protocol;  // the messages under test

/// Frame `step` with `tiles` full 16 x 16 tiles (about 2 KB each), neighbours and strings.
inline protocol::SensorFrame frame(std::uint64_t step, int tiles) {
  std::mt19937_64 rng(step * 7919 + 17);
  auto any_bits = [&] {
    const std::uint64_t b = rng();
    double d;
    std::memcpy(&d, &b, sizeof d);
    return d;
  };
  protocol::SensorFrame f;
  f.agent_id = 1;
  f.step = step;
  f.x_m = any_bits();
  f.y_m = any_bits();
  f.z_m = any_bits();
  f.material_m3 = any_bits();
  f.last_result = static_cast<protocol::ActionResult>(step % 4);
  f.last_reason = "step " + std::to_string(step) + " \xE2\x80\x94 r\xC3\xA9sultat";
  for (int t = 0; t < tiles; ++t) {
    protocol::TerrainTile tile{t / 8, t % 8, 16, 16, {}};
    tile.heights.resize(256);
    for (double& h : tile.heights) h = any_bits();
    f.tiles.push_back(std::move(tile));
  }
  for (std::uint32_t n = 2; n < 5; ++n) f.neighbours.push_back({n, any_bits(), any_bits(), any_bits(), any_bits()});
  f.run_over = step % 2 == 1;
  return f;
}

inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Every field equal, doubles bit for bit.
inline bool same(const protocol::SensorFrame& a, const protocol::SensorFrame& b) {
  if (a.agent_id != b.agent_id || a.step != b.step || !same_bits(a.x_m, b.x_m) || !same_bits(a.y_m, b.y_m) ||
      !same_bits(a.z_m, b.z_m) || !same_bits(a.material_m3, b.material_m3) || a.last_result != b.last_result ||
      a.last_reason != b.last_reason || a.run_over != b.run_over || a.tiles.size() != b.tiles.size() ||
      a.neighbours.size() != b.neighbours.size())
    return false;
  for (std::size_t i = 0; i < a.tiles.size(); ++i) {
    const protocol::TerrainTile& x = a.tiles[i];
    const protocol::TerrainTile& y = b.tiles[i];
    if (x.tile_row != y.tile_row || x.tile_col != y.tile_col || x.rows != y.rows || x.cols != y.cols ||
        x.heights.size() != y.heights.size() ||
        std::memcmp(x.heights.data(), y.heights.data(), x.heights.size() * sizeof(double)) != 0)
      return false;
  }
  for (std::size_t i = 0; i < a.neighbours.size(); ++i) {
    const protocol::Neighbour& x = a.neighbours[i];
    const protocol::Neighbour& y = b.neighbours[i];
    if (x.agent_id != y.agent_id || !same_bits(x.position.x, y.position.x) || !same_bits(x.position.y, y.position.y) || !same_bits(x.z_m, y.z_m) ||
        !same_bits(x.radius_m, y.radius_m))
      return false;
  }
  return true;
}

/// Where `got` first differs from `want` (empty when they are the same): the field, and for a tile's heights the
/// tile, the height and its byte offset in the tile's heights, so that a corrupted frame shows where it was hit.
inline std::string first_difference(const protocol::SensorFrame& got, const protocol::SensorFrame& want) {
  if (got.tiles.size() != want.tiles.size())
    return "tiles " + std::to_string(got.tiles.size()) + " instead of " + std::to_string(want.tiles.size());
  for (std::size_t i = 0; i < got.tiles.size(); ++i) {
    const protocol::TerrainTile& x = got.tiles[i];
    const protocol::TerrainTile& y = want.tiles[i];
    if (x.heights.size() != y.heights.size())
      return "tile " + std::to_string(i) + ": " + std::to_string(x.heights.size()) + " heights";
    for (std::size_t k = 0; k < x.heights.size(); ++k)
      if (!same_bits(x.heights[k], y.heights[k])) {
        std::size_t wrong = 0;
        for (std::size_t m = k; m < x.heights.size(); ++m) wrong += same_bits(x.heights[m], y.heights[m]) ? 0 : 1;
        return "tile " + std::to_string(i) + " height " + std::to_string(k) + " (byte " + std::to_string(k * 8) +
               "), " + std::to_string(wrong) + " of its heights from there differ";
      }
  }
  return same(got, want) ? "" : "a field outside the tiles";
}

}  // namespace marsala::probe
