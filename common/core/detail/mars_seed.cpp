#include "marsala/core/detail/mars_seed.hpp"

#include "marsala/core/detail/mars_pair.hpp"

#include <algorithm>
#include <cmath>

namespace marsala::detail {
namespace {

// Raster propagation (two sweeps, as in 8SSEDT) of each cell's best *foreign* source: the best
// other cell found so far, even while it stays below the cell's own height. Passing foreign
// sources through cells that are their own maximum lets a far source reach the cells it wins at
// behind them (e.g. on a plane slightly steeper than kappa, where no neighbour ever wins).
class ForeignSourcePropagation {
 public:
  // value[i] receives the best foreign value [m], src[i] the foreign source (-1: none).
  ForeignSourcePropagation(const Problem& pb, double* value, std::int32_t* src)
      : pb_(pb),
        value_(value),
        src_(src),
        row_of_(pb.cols),
        cone_(pb.kcs),
        drop_side_(pb.kcs * std::sqrt(1.0)),
        drop_diagonal_(pb.kcs * std::sqrt(2.0)) {}

  void run() {
    const int rows = pb_.rows, cols = pb_.cols;
    std::fill(src_, src_ + static_cast<std::int64_t>(rows) * cols, -1);
    std::fill(value_, value_ + static_cast<std::int64_t>(rows) * cols, -kInf);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (c > 0) take(r, c, 0, -1);
        if (r > 0) {
          if (c > 0) take(r, c, -1, -1);
          take(r, c, -1, 0);
          if (c + 1 < cols) take(r, c, -1, 1);
        }
      }
      for (int c = cols - 2; c >= 0; --c) take(r, c, 0, 1);
    }
    for (int r = rows - 1; r >= 0; --r) {
      for (int c = cols - 1; c >= 0; --c) {
        if (c + 1 < cols) take(r, c, 0, 1);
        if (r + 1 < rows) {
          if (c + 1 < cols) take(r, c, 1, 1);
          take(r, c, 1, 0);
          if (c > 0) take(r, c, 1, -1);
        }
      }
      for (int c = 1; c < cols; ++c) take(r, c, 0, -1);
    }
  }

 private:
  // Offers neighbour (r + dr, c + dc) itself and its foreign source to cell (r, c).
  void take(int r, int c, int dr, int dc) {
    const std::int64_t i = static_cast<std::int64_t>(r) * pb_.cols + c;
    const std::int64_t n = i + static_cast<std::int64_t>(dr) * pb_.cols + dc;
    if (n != src_[i]) {
      // Same bits as cone_value(h, kcs, 1) and cone_value(h, kcs, 2).
      const double v = pb_.h[n] - (dr != 0 && dc != 0 ? drop_diagonal_ : drop_side_);
      if (v > value_[i]) {
        value_[i] = v;
        src_[i] = static_cast<std::int32_t>(n);
      }
    }
    const std::int32_t s = src_[n];
    if (s < 0 || s == i || s == src_[i]) return;
    const int sr = row_of_(s);
    const long long er = r - sr, ec = c - (s - static_cast<std::int64_t>(sr) * pb_.cols);
    const double v = cone_(pb_.h[s], er * er + ec * ec);
    if (v > value_[i]) {
      value_[i] = v;
      src_[i] = s;
    }
  }

  const Problem& pb_;
  double* value_;
  std::int32_t* src_;
  RowOf row_of_;
  ConeValues cone_;
  double drop_side_, drop_diagonal_;
};

// Makes every dropped cell point straight at a surviving source that dominates it within tol,
// re-checked directly against the root of its pointer chain, so that tolerances never add up
// along a chain; a cell failing the direct check survives. Pointers always climb in height
// (tol < kcs), so chains end.
void resolve_chains(const Problem& pb, std::int32_t* src) {
  const RowOf row_of(pb.cols);
  const ConeValues cone(pb.kcs);
  const std::int64_t n = static_cast<std::int64_t>(pb.rows) * pb.cols;
  auto resolved = [&](std::int64_t i) { return src[i] == i || src[src[i]] == src[i]; };
  std::vector<std::int32_t> chain;
  for (std::int64_t start = 0; start < n; ++start) {
    if (resolved(start)) continue;
    chain.clear();
    for (std::int64_t i = start; !resolved(i); i = src[i]) chain.push_back(static_cast<std::int32_t>(i));
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const std::int32_t q = *it;
      const std::int32_t root = src[src[q]];  // src[q] is resolved: a survivor or points at one
      const int qr = row_of(q), rr = row_of(root);
      const long long dr = qr - rr;
      const long long dc =
          (q - static_cast<std::int64_t>(qr) * pb.cols) - (root - static_cast<std::int64_t>(rr) * pb.cols);
      src[q] = cone(pb.h[root], dr * dr + dc * dc) >= pb.h[q] - pb.tol ? root : q;
    }
  }
}

// One offset of the local pass: (dr, dc) [cells] and its drop kcs sqrt(dr^2 + dc^2) [m].
struct LocalOffset {
  int dr, dc;
  double drop;
};

// The local pass on kPairs pairs of cells (out, kept in registers across all offsets: one load and store of the
// output) from the padded input rows starting at `in` (at_offset[k]: where offset k reads from there).
template <int kPairs>
void apply_chunk(const std::vector<LocalOffset>& offsets, const std::vector<std::ptrdiff_t>& at_offset,
                 const double* in, double* out) {
  Pair a[kPairs];
  for (int p = 0; p < kPairs; ++p) a[p] = load(out + 2 * p);
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    const double* at = in + at_offset[k];
    const double drop = offsets[k].drop;
    for (int p = 0; p < kPairs; ++p) a[p] = max(load(at + 2 * p) - drop, a[p]);
  }
  for (int p = 0; p < kPairs; ++p) store(out + 2 * p, a[p]);
}

}  // namespace

std::vector<std::uint64_t> seed_lower_bound(const Problem& pb, double* lower) {
  const std::int64_t n = static_cast<std::int64_t>(pb.rows) * pb.cols;
  std::vector<std::int32_t> src(static_cast<std::size_t>(n));
  ForeignSourcePropagation(pb, lower, src.data()).run();
  for (std::int64_t i = 0; i < n; ++i) {
    if (src[i] < 0 || lower[i] < pb.h[i] - pb.tol) src[i] = static_cast<std::int32_t>(i);
    lower[i] = std::max(lower[i], pb.h[i]);
  }
  resolve_chains(pb, src.data());
  const int leaf_cols = (pb.cols + kBlock - 1) / kBlock, leaf_rows = (pb.rows + kBlock - 1) / kBlock;
  std::vector<std::uint64_t> masks(static_cast<std::size_t>(leaf_rows) * leaf_cols, 0);
  for (int r = 0; r < pb.rows; ++r)
    for (int c = 0; c < pb.cols; ++c) {
      const std::int64_t i = static_cast<std::int64_t>(r) * pb.cols + c;
      if (src[i] == i)
        masks[static_cast<std::size_t>(r / kBlock) * leaf_cols + c / kBlock] |= std::uint64_t{1}
                                                                                << ((r % kBlock) * kBlock + c % kBlock);
    }
  return masks;
}

void apply_local_sources(const Problem& pb, double* lower, const std::uint8_t* wanted_rows) {
  std::vector<LocalOffset> offsets;
  int radius = 0;
  while ((radius + 1) * (radius + 1) <= kLocalRadius2) ++radius;
  for (int dr = -radius; dr <= radius; ++dr)
    for (int dc = -radius; dc <= radius; ++dc) {
      const long long d2 = static_cast<long long>(dr) * dr + static_cast<long long>(dc) * dc;
      if (d2 > 0 && d2 <= kLocalRadius2)
        offsets.push_back(LocalOffset{dr, dc, pb.kcs * std::sqrt(static_cast<double>(d2))});
    }
  const int cols = pb.cols, rows = pb.rows;
  // The input rows r - radius .. r + radius, each with radius cells at -inf on its left and at least radius + kChunk on
  // its right, and rows off the grid all -inf: every offset of every cell then reads inside these rows, so every
  // cell takes the chunked loop below (a source at -inf is below every value, as a missing one is). A ring of
  // 2 radius + 1 rows, each row stored twice (slots k and k + 2 radius + 1) so that the rows around r are always
  // consecutive: the extra memory is O(cols).
  constexpr int kChunk = 16;
  const int chunks = (cols + kChunk - 1) / kChunk;
  const int padded = chunks * kChunk + 2 * radius;
  const int ring_rows = 2 * radius + 1;
  std::vector<double> ring(static_cast<std::size_t>(2 * ring_rows) * padded, -kInf);
  auto load_row = [&](int sr) {  // input row sr (or -inf off the grid) into both its ring slots
    const int slot = (sr + ring_rows) % ring_rows;
    for (int copy = 0; copy < 2; ++copy) {
      double* row = ring.data() + static_cast<std::size_t>(slot + copy * ring_rows) * padded;
      std::fill(row, row + padded, -kInf);
      if (sr >= 0 && sr < rows)
        std::copy(pb.h + static_cast<std::int64_t>(sr) * cols, pb.h + static_cast<std::int64_t>(sr + 1) * cols,
                  row + radius);
    }
  };
  for (int sr = -radius; sr < radius; ++sr) load_row(sr);
  std::vector<std::ptrdiff_t> at_offset(offsets.size());  // where an offset reads, from the ring's row r - radius
  for (std::size_t k = 0; k < offsets.size(); ++k)
    at_offset[k] = static_cast<std::ptrdiff_t>(offsets[k].dr + radius) * padded + radius + offsets[k].dc;
  alignas(16) double tail[kChunk];
  for (int r = 0; r < rows; ++r) {
    load_row(r + radius);
    if (wanted_rows && !wanted_rows[r]) continue;
    const double* first = ring.data() + static_cast<std::size_t>((r - radius + ring_rows) % ring_rows) * padded;
    double* out = lower + static_cast<std::int64_t>(r) * cols;
    for (int c = 0; c < cols; c += kChunk) {
      // max(v, out) is out < v ? v : out: the same bits as cone_value(), in the same order of offsets as ever.
      if (c + kChunk <= cols) {
        apply_chunk<kChunk / 2>(offsets, at_offset, first + c, out + c);
        continue;
      }
      // The last, partial chunk through a buffer, as few pairs as it holds (41 columns: 16 + 16 + 5 pairs).
      const int pairs = (cols - c + 1) / 2;
      std::fill(tail, tail + kChunk, -kInf);
      std::copy(out + c, out + cols, tail);
      switch (pairs) {
        case 1: apply_chunk<1>(offsets, at_offset, first + c, tail); break;
        case 2: apply_chunk<2>(offsets, at_offset, first + c, tail); break;
        case 3: apply_chunk<3>(offsets, at_offset, first + c, tail); break;
        case 4: apply_chunk<4>(offsets, at_offset, first + c, tail); break;
        case 5: apply_chunk<5>(offsets, at_offset, first + c, tail); break;
        case 6: apply_chunk<6>(offsets, at_offset, first + c, tail); break;
        case 7: apply_chunk<7>(offsets, at_offset, first + c, tail); break;
        default: apply_chunk<8>(offsets, at_offset, first + c, tail); break;
      }
      std::copy(tail, tail + (cols - c), out + c);
    }
  }
}

}  // namespace marsala::detail
