#include "marsala/terrain/terrain_stats.hpp"

#include <algorithm>
#include <cmath>

namespace marsala::terrain {
namespace {

// Derivative along one axis at index i of n samples: central inside, one-sided at the borders, 0 when n == 1.
template <typename Height>
double derivative(Height height, int i, int n, double cs) {
  if (n == 1) return 0.0;
  const int lo = std::max(i - 1, 0);
  const int hi = std::min(i + 1, n - 1);
  return (height(hi) - height(lo)) / ((hi - lo) * cs);
}

}  // namespace

TerrainStats compute_terrain_stats(const Heightmap& map) {
  TerrainStats s;
  s.rows = map.rows();
  s.cols = map.cols();
  s.cell_size_m = map.cell_size_m();
  s.width_m = map.cols() * map.cell_size_m();
  s.height_m = map.rows() * map.cell_size_m();
  s.min_height_m = map.min_height();
  s.max_height_m = map.max_height();
  s.mean_height_m = map.heights().mean();
  const double cs = map.cell_size_m();
  double slope_sum = 0.0;
  for (int r = 0; r < map.rows(); ++r)
    for (int c = 0; c < map.cols(); ++c) {
      const double dx = derivative([&](int cc) { return map(r, cc); }, c, map.cols(), cs);
      const double dy = derivative([&](int rr) { return map(rr, c); }, r, map.rows(), cs);
      const double slope = std::hypot(dx, dy);
      slope_sum += slope;
      s.max_slope = std::max(s.max_slope, slope);
    }
  s.mean_slope = slope_sum / static_cast<double>(map.size());
  return s;
}

}  // namespace marsala::terrain
