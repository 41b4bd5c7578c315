#include "marsala/core/navigability_processor.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "marsala/core/detail/navigability_kernel.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala {
namespace {

void require(bool ok, const char* name, double value, const char* rule) {
  if (!ok) throw InvalidArgument(fmt::format("NavigabilityProcessor: {} must be {}, got {}", name, rule, value));
}

void check_finite(const Heightmap& h) {
  const double* heights = h.data();
  const long long n = h.size();
  for (long long i = 0; i < n; ++i)
    if (!std::isfinite(heights[i])) {
      const CellIndex cell{static_cast<int>(i / h.cols()), static_cast<int>(i % h.cols())};
      throw InvalidArgument(
          fmt::format("NavigabilityProcessor: height at cell {} is not finite ({})", cell, heights[i]));
    }
}

void check_origin(int rows, int cols, CellIndex origin) {
  if (origin.row < 0 || origin.row >= rows || origin.col < 0 || origin.col >= cols)
    throw InvalidArgument(fmt::format("NavigabilityProcessor: origin {} is off the {} x {} grid", origin, rows, cols));
}

/// The origin's 8-connected component of the occupiable cells, one bit per cell, each row in words of 64 cells: rows
/// are swept down and up, each row taking what its neighbour rows reach (8 neighbours: the row above and below
/// widened by a cell each way) and then the whole runs of occupiable cells that hold a reached cell (the cells of a
/// run are neighbours in a row). The sweeps stop when a pair of them reaches nothing new, or after kSweeps pairs (a
/// maze), when a search from every cell reached so far finishes the component.
class BitFill {
 public:
  BitFill(const CellMask& occupiable, CellIndex origin)
      : rows_(static_cast<int>(occupiable.rows())),
        cols_(static_cast<int>(occupiable.cols())),
        words_((cols_ + 63) / 64),
        occ_(static_cast<std::size_t>(rows_) * words_, 0),
        reach_(occ_.size(), 0),
        seed_(static_cast<std::size_t>(words_), 0) {
    for (int r = 0; r < rows_; ++r)
      for (int c = 0; c < cols_; ++c)
        if (occupiable(r, c) != 0) occ_[index(r, c / 64)] |= bit(c);
    reach_[index(origin.row, origin.col / 64)] |= bit(origin.col);
  }

  /// The component as a mask of the grid's shape.
  CellMask run() {
    bool grew = true;
    for (int pair = 0; pair < kSweeps && grew; ++pair) {
      grew = false;
      for (int r = 0; r < rows_; ++r) grew |= take_row(r);
      for (int r = rows_ - 1; r >= 0; --r) grew |= take_row(r);
    }
    if (grew) finish_by_search();
    CellMask out = CellMask::Zero(rows_, cols_);
    for (int r = 0; r < rows_; ++r)
      for (int w = 0; w < words_; ++w)
        for (std::uint64_t bits = reach_[index(r, w)]; bits != 0; bits &= bits - 1)
          out(r, w * 64 + __builtin_ctzll(bits)) = 1;
    return out;
  }

 private:
  static constexpr int kSweeps = 8;

  /// Word w of row r.
  std::size_t index(int r, int w) const { return static_cast<std::size_t>(r) * words_ + w; }
  /// Column c's bit in its word.
  static std::uint64_t bit(int c) { return std::uint64_t{1} << (c % 64); }

  /// Bits of `seed` (within `run`) spread towards higher bits along runs of set bits of `run`.
  static std::uint64_t fill_up(std::uint64_t seed, std::uint64_t run) {
    seed |= run & (seed << 1), run &= run << 1;
    seed |= run & (seed << 2), run &= run << 2;
    seed |= run & (seed << 4), run &= run << 4;
    seed |= run & (seed << 8), run &= run << 8;
    seed |= run & (seed << 16), run &= run << 16;
    return seed | (run & (seed << 32));
  }
  /// The same towards lower bits.
  static std::uint64_t fill_down(std::uint64_t seed, std::uint64_t run) {
    seed |= run & (seed >> 1), run &= run >> 1;
    seed |= run & (seed >> 2), run &= run >> 2;
    seed |= run & (seed >> 4), run &= run >> 4;
    seed |= run & (seed >> 8), run &= run >> 8;
    seed |= run & (seed >> 16), run &= run >> 16;
    return seed | (run & (seed >> 32));
  }

  /// Word w of row r widened by a cell each way (across word boundaries); 0 off the grid.
  std::uint64_t widened(int r, int w) const {
    if (r < 0 || r >= rows_) return 0;
    const std::uint64_t x = reach_[index(r, w)];
    std::uint64_t out = x | (x << 1) | (x >> 1);
    if (w > 0) out |= reach_[index(r, w - 1)] >> 63;
    if (w + 1 < words_) out |= reach_[index(r, w + 1)] << 63;
    return out;
  }

  /// Row r takes the cells its neighbour rows reach and the whole runs that hold one; true when it grew.
  bool take_row(int r) {
    std::uint64_t* row = &reach_[index(r, 0)];
    const std::uint64_t* occ = &occ_[index(r, 0)];
    std::uint64_t* seed = seed_.data();
    const int words = words_;
    for (int w = 0; w < words; ++w) seed[w] = (row[w] | widened(r - 1, w) | widened(r + 1, w)) & occ[w];
    for (int w = 0; w < words; ++w) {  // upwards, carrying a run across into the next word
      if (w > 0 && (seed[w - 1] >> 63) != 0) seed[w] |= occ[w] & 1;
      seed[w] = fill_up(seed[w], occ[w]);
    }
    for (int w = words - 1; w >= 0; --w) {  // downwards
      if (w + 1 < words && (seed[w + 1] & 1) != 0) seed[w] |= occ[w] & (std::uint64_t{1} << 63);
      seed[w] = fill_down(seed[w], occ[w]);
    }
    bool grew = false;
    for (int w = 0; w < words; ++w) {
      grew |= seed[w] != row[w];
      row[w] = seed[w];
    }
    return grew;
  }

  /// A depth-first search from every reached cell through the occupiable cells.
  void finish_by_search() {
    std::vector<CellIndex> frontier;
    auto reached = [&](int r, int c) { return (reach_[index(r, c / 64)] & bit(c)) != 0; };
    for (int r = 0; r < rows_; ++r)
      for (int c = 0; c < cols_; ++c)
        if (reached(r, c)) frontier.push_back({r, c});
    while (!frontier.empty()) {
      const CellIndex cell = frontier.back();
      frontier.pop_back();
      for (int r = std::max(cell.row - 1, 0); r <= std::min(cell.row + 1, rows_ - 1); ++r)
        for (int c = std::max(cell.col - 1, 0); c <= std::min(cell.col + 1, cols_ - 1); ++c) {
          if ((occ_[index(r, c / 64)] & bit(c)) == 0 || reached(r, c)) continue;
          reach_[index(r, c / 64)] |= bit(c);
          frontier.push_back({r, c});
        }
    }
  }

  int rows_, cols_, words_;
  std::vector<std::uint64_t> occ_, reach_;
  std::vector<std::uint64_t> seed_;  ///< one row's cells being taken
};

}  // namespace

NavigabilityProcessor::NavigabilityProcessor(NavigabilityParams params) : params_(params) {
  require(std::isfinite(params_.kappa) && params_.kappa > 0.0, "kappa", params_.kappa, "finite and > 0 [m/m]");
  require(std::isfinite(params_.delta_m) && params_.delta_m > 0.0, "delta_m", params_.delta_m, "finite and > 0 [m]");
  require(std::isfinite(params_.eps_m) && params_.eps_m >= 0.0, "eps_m", params_.eps_m, "finite and >= 0 [m]");
}

CellMask NavigabilityProcessor::occupiable(const Heightmap& h) const {
  check_finite(h);
  return detail::occupiable_mask(h, params_);
}

CellMask NavigabilityProcessor::navigable(const Heightmap& h, CellIndex origin) const {
  check_origin(h.rows(), h.cols(), origin);
  return navigable_from(occupiable(h), origin);
}

CellMask NavigabilityProcessor::navigable_from(const CellMask& occupiable, CellIndex origin) {
  const int rows = static_cast<int>(occupiable.rows()), cols = static_cast<int>(occupiable.cols());
  check_origin(rows, cols, origin);
  if (occupiable(origin.row, origin.col) == 0) return CellMask::Zero(rows, cols);
  return BitFill(occupiable, origin).run();
}

}  // namespace marsala
