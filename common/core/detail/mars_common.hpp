#pragma once
// Shared definitions of the MARS processor internals. All geometry is in cell units (row, col);
// heights are metres; kcs = kappa * cell size is the drop per cell of distance [m/cell].

#include <cmath>
#include <cstdint>
#include <limits>

namespace marsala::detail {

/// Side of a source leaf and of a target block [cells]; one 64-bit mask per leaf.
inline constexpr int kBlock = 8;
/// Sources with dr^2 + dc^2 <= this are applied densely to every cell [cells^2].
inline constexpr int kLocalRadius2 = 25;
/// Positive infinity [m].
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// The grid and parameters of one projection.
struct Problem {
  const double* h = nullptr;  ///< row-major heights [m]
  int rows = 0;               ///< grid rows [cells]
  int cols = 0;               ///< grid columns [cells]
  double kcs = 0.0;           ///< kappa * cell size [m/cell]
  double tol = 0.0;           ///< tie tolerance for domination and pruning [m]
};

/// Value of a source of height h_source [m] at squared distance d2 [cells^2]: the one formula
/// used everywhere, so that ties present in the input (a MARS output fed back) are seen bit for bit.
inline double cone_value(double h_source, double kcs, long long d2) {
  return h_source - kcs * std::sqrt(static_cast<double>(d2));
}

/// cone_value() with the drops kcs sqrt(d2) of the nearer distances read from a table: the same bits, without the
/// square root's latency in the raster sweeps, where most sources are a few cells away.
class ConeValues {
 public:
  explicit ConeValues(double kcs) : kcs_(kcs) {
    for (int d2 = 0; d2 < kSize; ++d2) drop_[d2] = kcs * std::sqrt(static_cast<double>(d2));
  }
  /// cone_value(h_source, kcs, d2) [m].
  double operator()(double h_source, long long d2) const {
    return d2 < kSize ? h_source - drop_[d2] : cone_value(h_source, kcs_, d2);
  }

 private:
  static constexpr int kSize = 1024;
  double kcs_;
  double drop_[kSize];
};

/// Row of a linear index in a grid of `cols` columns by one multiplication: q = (i m) >> k with k = 32 +
/// ceil(log2 cols) and m = ceil(2^k / cols) < 2^33 is floor(i / cols) exactly for every i < 2^31 (m cols = 2^k + e
/// with e < cols, and i e < 2^k keeps the rounding below one row); i m < 2^64.
class RowOf {
 public:
  explicit RowOf(int cols) {
    int log2 = 0;
    while ((1LL << log2) < cols) ++log2;
    shift_ = 32 + log2;
    magic_ = ((std::uint64_t{1} << shift_) + static_cast<std::uint64_t>(cols) - 1) / static_cast<std::uint64_t>(cols);
  }
  /// floor(i / cols) for 0 <= i < 2^31.
  int operator()(long long i) const { return static_cast<int>((static_cast<std::uint64_t>(i) * magic_) >> shift_); }

 private:
  std::uint64_t magic_ = 1;
  int shift_ = 32;
};

}  // namespace marsala::detail
