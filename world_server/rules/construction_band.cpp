#include "marsala/world_server/rules/construction_band.hpp"

#include <algorithm>

#include "marsala/core/error.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/robot_type.hpp"

namespace marsala::world_server {

double construction_band_width_m(const WorldState& state) {
  double width = state.payload_path.navigability.delta_m;
  for (const AgentRecord& a : state.agents) width = std::max(width, construction_params(a.type).delta_m);
  return width;
}

const std::vector<CellIndex>& band_route_cells(const WorldState& state, const std::optional<PayloadRoute>& final_path) {
  return final_path ? final_path->cells : state.check.route.route;
}

CellMask construction_band(const std::vector<CellIndex>& route, int rows, int cols, double cell_size_m,
                           double width_m) {
  CellMask band = CellMask::Zero(rows, cols);
  const std::vector<CellIndex> ball = disc_offsets(width_m / (2.0 * cell_size_m));
  for (const CellIndex& c : route)
    for (const CellIndex& o : ball) {
      const int r = c.row + o.row, k = c.col + o.col;
      if (r >= 0 && k >= 0 && r < rows && k < cols) band(r, k) = 1;
    }
  return band;
}

double deposited_outside_band_m3(const Heightmap& initial, const Heightmap& final_terrain, const CellMask& band) {
  if (initial.rows() != final_terrain.rows() || initial.cols() != final_terrain.cols() ||
      band.rows() != initial.rows() || band.cols() != initial.cols())
    throw InvalidArgument(fmt::format("deposited outside the band: initial terrain {} x {}, final {} x {} and band {} "
                                      "x {} differ",
                                      initial.rows(), initial.cols(), final_terrain.rows(), final_terrain.cols(),
                                      band.rows(), band.cols()));
  double sum = 0.0;
  for (int r = 0; r < initial.rows(); ++r)
    for (int c = 0; c < initial.cols(); ++c)
      if (band(r, c) == 0) sum += std::max(0.0, final_terrain(r, c) - initial(r, c));
  return sum * initial.cell_size_m() * initial.cell_size_m();
}

BandReport band_report(const WorldState& state, const Heightmap& initial,
                       const std::optional<PayloadRoute>& final_path) {
  BandReport report;
  report.width_m = construction_band_width_m(state);
  const Heightmap& terrain = state.terrain;
  report.outside_m3 = deposited_outside_band_m3(
      initial, terrain,
      construction_band(band_route_cells(state, final_path), terrain.rows(), terrain.cols(), terrain.cell_size_m(),
                        report.width_m));
  return report;
}

}  // namespace marsala::world_server
