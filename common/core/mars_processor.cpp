#include "marsala/core/mars_processor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "marsala/core/detail/mars_common.hpp"
#include "marsala/core/detail/mars_search.hpp"
#include "marsala/core/detail/mars_seed.hpp"
#include "marsala/core/detail/mars_source_tree.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala {
namespace {

constexpr double kAbsoluteTolM = 1e-10;  // tie tolerance [m] ...
constexpr double kRelativeTol = 1e-15;   // ... grown with the magnitudes of heights and drops

}  // namespace

std::string mars_problem(double kappa, double cell_size_m, double max_abs_height_m, int rows, int cols) {
  const double rise_m = kappa * cell_size_m;
  const double magnitude_m =
      std::abs(max_abs_height_m) + rise_m * std::hypot(static_cast<double>(rows), static_cast<double>(cols));
  if (!std::isfinite(rise_m) || !std::isfinite(magnitude_m))
    return fmt::format("kappa {} x cell size {} m over a {} x {} grid with heights up to {} m overflows doubles", kappa,
                       cell_size_m, rows, cols, max_abs_height_m);
  const double spacing_m = std::nextafter(magnitude_m, std::numeric_limits<double>::infinity()) - magnitude_m;
  if (!(rise_m > 16.0 * spacing_m))
    return fmt::format(
        "kappa {} x cell size {} m = {} m per cell is lost in rounding at heights of {} m (doubles there are {} m "
        "apart): MARS cannot be computed; use a steeper kappa, larger cells or heights nearer 0",
        kappa, cell_size_m, rise_m, max_abs_height_m, spacing_m);
  return {};
}

MarsProcessor::MarsProcessor(double kappa) : kappa_(kappa) {
  if (!std::isfinite(kappa) || !(kappa > 0.0))
    throw InvalidArgument(fmt::format("MarsProcessor: kappa must be finite and > 0, got {}", kappa));
}

Heightmap MarsProcessor::project(const Heightmap& h) const { return solve(h, nullptr); }

Heightmap MarsProcessor::project(const Heightmap& h, const CellMask& wanted) const {
  if (wanted.rows() != h.rows() || wanted.cols() != h.cols())
    throw InvalidArgument(fmt::format("MarsProcessor: the wanted cells are {} x {} but the heights {} x {}",
                                      wanted.rows(), wanted.cols(), h.rows(), h.cols()));
  return solve(h, &wanted);
}

Heightmap MarsProcessor::solve(const Heightmap& h, const CellMask* wanted) const {
  Heightmap out = h;
  const int rows = h.rows(), cols = h.cols();
  if (rows <= 0 || cols <= 0) return out;
  if (h.size() >= std::numeric_limits<std::int32_t>::max())
    throw InvalidArgument(fmt::format("MarsProcessor: a grid of {} cells is too large", h.size()));
  double max_abs = 0.0;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double v = h(r, c);
      if (!std::isfinite(v))
        throw InvalidArgument(fmt::format("MarsProcessor: height at cell (row {}, col {}) is not finite", r, c));
      max_abs = std::max(max_abs, std::abs(v));
    }
  if (const std::string problem = mars_problem(kappa_, h.cell_size_m(), max_abs, rows, cols); !problem.empty())
    throw InvalidArgument(fmt::format("MarsProcessor: {}", problem));
  detail::Problem pb;
  pb.h = h.data();
  pb.rows = rows;
  pb.cols = cols;
  pb.kcs = kappa_ * h.cell_size_m();
  const double longest_drop = pb.kcs * std::hypot(static_cast<double>(rows), static_cast<double>(cols));
  pb.tol = std::max(kAbsoluteTolM, kRelativeTol * (max_abs + longest_drop));
  // Pointer chains of dominated cells must climb (by kcs - tol per step) to end.
  pb.tol = std::min(pb.tol, 0.25 * pb.kcs);

  double* lower = out.data();
  if (!wanted) {
    std::vector<std::uint64_t> sources = detail::seed_lower_bound(pb, lower);
    detail::apply_local_sources(pb, lower);
    const detail::SourceTree tree(pb, std::move(sources));
    detail::search_sources(pb, tree, lower);
    return out;
  }
  // The wanted targets by row (the local pass) and by block of the search (its bit layout); each target's value
  // depends on its own limit alone, so the rows and blocks left out change no wanted cell.
  std::vector<std::uint8_t> wanted_rows(static_cast<std::size_t>(rows), 0);
  const int block_cols = (cols + detail::kBlock - 1) / detail::kBlock;
  const int block_rows = (rows + detail::kBlock - 1) / detail::kBlock;
  std::vector<std::uint64_t> wanted_blocks(static_cast<std::size_t>(block_rows) * block_cols, 0);
  bool any = false;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if ((*wanted)(r, c) != 0) {
        any = true;
        wanted_rows[static_cast<std::size_t>(r)] = 1;
        wanted_blocks[static_cast<std::size_t>(r / detail::kBlock) * block_cols + c / detail::kBlock] |=
            std::uint64_t{1} << ((r % detail::kBlock) * detail::kBlock + c % detail::kBlock);
      }
  if (!any) return out;
  std::vector<std::uint64_t> sources = detail::seed_lower_bound(pb, lower);
  detail::apply_local_sources(pb, lower, wanted_rows.data());
  const detail::SourceTree tree(pb, std::move(sources));
  detail::search_sources(pb, tree, lower, wanted_blocks.data());
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if ((*wanted)(r, c) == 0) out(r, c) = h(r, c);
  return out;
}

Heightmap MarsProcessor::gap(const Heightmap& h) const {
  Heightmap g = project(h);
  g.heights() -= h.heights();
  return g;
}

}  // namespace marsala
