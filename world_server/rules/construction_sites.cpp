#include "marsala/world_server/rules/construction_sites.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala::world_server {

std::vector<ConstructionSite> construction_sites(const Heightmap& initial, const Heightmap& final_terrain,
                                                 const PayloadRoute& route, double min_gap_m) {
  if (initial.rows() != final_terrain.rows() || initial.cols() != final_terrain.cols())
    throw InvalidArgument(fmt::format("construction sites: initial terrain {} x {} and final terrain {} x {} differ",
                                      initial.rows(), initial.cols(), final_terrain.rows(), final_terrain.cols()));
  const int rows = final_terrain.rows(), cols = final_terrain.cols();
  const double cs = final_terrain.cell_size_m();
  const auto raised = [&](int r, int c) { return final_terrain(r, c) - initial(r, c) > kRaisedM; };
  for (const CellIndex& c : route.cells)
    if (!final_terrain.contains(c))
      throw InvalidArgument(fmt::format("construction sites: route cell {} is off the grid", c));

  // Regions of raised cells, labelled on demand from the route (flood fill, 8-connected).
  std::vector<int> region(static_cast<std::size_t>(rows) * cols, -1);
  std::vector<std::pair<double, std::int64_t>> regions;  // volume, cells
  const auto label = [&](CellIndex seed) {
    const int id = static_cast<int>(regions.size());
    regions.push_back({0.0, 0});
    std::vector<CellIndex> stack{seed};
    region[static_cast<std::size_t>(seed.row) * cols + seed.col] = id;
    while (!stack.empty()) {
      const CellIndex p = stack.back();
      stack.pop_back();
      regions.back().first += (final_terrain(p.row, p.col) - initial(p.row, p.col)) * cs * cs;
      ++regions.back().second;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const int r = p.row + dr, c = p.col + dc;
          if (r < 0 || c < 0 || r >= rows || c >= cols || !raised(r, c)) continue;
          int& slot = region[static_cast<std::size_t>(r) * cols + c];
          if (slot >= 0) continue;
          slot = id;
          stack.push_back({r, c});
        }
    }
    return id;
  };

  std::vector<ConstructionSite> sites;
  std::vector<bool> counted;
  double along = 0.0;
  for (std::size_t i = 0; i < route.cells.size(); ++i) {
    const CellIndex c = route.cells[i];
    if (i > 0) {
      const CellIndex p = route.cells[i - 1];
      along += (p.row != c.row && p.col != c.col) ? cs * std::sqrt(2.0) : cs;
    }
    if (!raised(c.row, c.col)) continue;
    if (sites.empty() || along - sites.back().to_m >= min_gap_m) sites.push_back({along, along, 0.0, 0});
    sites.back().to_m = along;
    int id = region[static_cast<std::size_t>(c.row) * cols + c.col];
    if (id < 0) id = label(c);
    if (static_cast<std::size_t>(id) >= counted.size()) counted.resize(static_cast<std::size_t>(id) + 1, false);
    if (!counted[static_cast<std::size_t>(id)]) {
      counted[static_cast<std::size_t>(id)] = true;
      sites.back().volume_m3 += regions[static_cast<std::size_t>(id)].first;
      sites.back().cells += regions[static_cast<std::size_t>(id)].second;
    }
  }
  return sites;
}

}  // namespace marsala::world_server
