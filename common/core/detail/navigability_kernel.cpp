#include "marsala/core/detail/navigability_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

namespace marsala::detail {
namespace {

using Flags = std::uint16_t;
/// Ring groups tracked per cell (one bit each).
constexpr int kFlagBits = 16;
/// Rows of a strip in the ring-flag dilation (plus a halo of max_ring rows on each side).
constexpr int kStripRows = 64;
/// Largest lens-bitset table (in 64-bit words) the automatic marking accepts: 4 MB.
constexpr std::size_t kMaxLensTableWords = std::size_t{1} << 19;
/// In span marking, how many cleared lenses between two checks of the whole ball.
constexpr int kSpanChecksEvery = 8;
/// Side of the tiles [cells] that summarise, before pass two, where occupiable cells remain.
constexpr int kTileShift = 3;

/// A partner offset v = q - r of a candidate low end r.
struct Partner {
  int dr = 0;
  int dc = 0;
  std::ptrdiff_t offset = 0;  // dr * cols + dc
  double threshold_m = 0.0;   // eps + kappa |v| + tolerance: a pair violates when h(q) - h(r) exceeds it
};

/// Ball, partner offsets and lens tables for one grid shape and cell size.
struct Stencil {
  int reach = 0;                               // ball half-width table covers |dr| <= reach
  std::vector<int> half_width;                 // [dr + reach]: ball row dr holds |dc| <= half_width
  int ball_reach = 0;                          // min(reach, rows - 1): ball rows that can lie on the grid
  std::vector<int> ball_width;                 // [dr + ball_reach]: min(half_width, cols - 1)
  std::vector<int> ball_first_bit;             // [dr + ball_reach]: bit of (dr, -ball_width)
  std::vector<std::ptrdiff_t> ball_offset;     // [bit]: dr * cols + dc
  int max_ring = 0;                            // largest Chebyshev ring holding a partner
  int partner_rows = 0, partner_cols = 0;      // largest |dr| and |dc| of a partner
  std::vector<Partner> partners;               // ordered by ring, then length (nearest first)
  std::vector<std::ptrdiff_t> partner_offset;  // partners[i].offset, packed for the interior scan
  std::vector<double> partner_threshold_m;     // partners[i].threshold_m, packed for the interior scan
  std::vector<int> ring_begin;                 // ring k holds partners [ring_begin[k], ring_begin[k + 1])
  std::vector<double> ring_threshold_m;        // [k]: eps + kappa * cs * k, a lower bound of ring k's thresholds
  std::vector<Flags> ring_bit;                 // [k]: flag bit of ring k's group
  int lens_words = 0;                          // 64-bit words per lens bitset (0 when marking spans)
  std::vector<std::uint64_t> lens_bits;        // partners.size() * lens_words
};

int ring_group(int k, int max_ring) {
  if (max_ring <= kFlagBits) return k - 1;
  return static_cast<int>(static_cast<long long>(k - 1) * kFlagBits / max_ring);
}

bool in_ball(long long dr, long long dc, double limit) { return static_cast<double>(dr * dr + dc * dc) <= limit; }

/// Largest |dc| with (dr, dc) in the ball, or -1 when row dr misses it; capped at `cap`.
int ball_half_width(int dr, double limit, int cap) {
  if (!in_ball(dr, 0, limit)) return -1;
  const double room = limit - static_cast<double>(static_cast<long long>(dr) * dr);
  if (room >= static_cast<double>(cap) * cap) return cap;
  int w = static_cast<int>(std::sqrt(room));
  while (w + 1 <= cap && in_ball(dr, w + 1, limit)) ++w;
  while (w > 0 && !in_ball(dr, w, limit)) --w;
  return w;
}

Stencil build_stencil(const NavigabilityParams& params, int rows, int cols, double cs, LensMarking marking) {
  Stencil s;
  // Same test as disc_offsets, computed row by row so that huge balls stay cheap: only offsets
  // within 2 * max(rows, cols) can matter on this grid.
  const double radius_cells = params.delta_m / (2.0 * cs);
  const double limit = radius_cells * radius_cells + tolerance::kBallCells2;
  const int cap = 2 * std::max(rows, cols);
  while (s.reach < cap && in_ball(s.reach + 1, 0, limit)) ++s.reach;
  const int reach = s.reach;
  s.half_width.resize(2 * reach + 1);
  for (int dr = -reach; dr <= reach; ++dr) s.half_width[dr + reach] = ball_half_width(dr, limit, cap);
  auto half_width = [&](int dr) { return std::abs(dr) <= reach ? s.half_width[dr + reach] : -1; };

  // Ball cells that can lie on the grid around an on-grid cell, as bits.
  s.ball_reach = std::min(reach, rows - 1);
  int bits = 0;
  for (int dr = -s.ball_reach; dr <= s.ball_reach; ++dr) {
    const int w = std::min(half_width(dr), cols - 1);
    s.ball_width.push_back(w);
    s.ball_first_bit.push_back(bits);
    for (int dc = -w; dc <= w; ++dc) s.ball_offset.push_back(static_cast<std::ptrdiff_t>(dr) * cols + dc);
    bits += 2 * w + 1;
  }

  // Partners: offsets v = q - r whose lens B ∩ (v + B) is non-empty (row s of B + B is the widest sum of
  // two ball rows), limited to the grid's extent.
  struct Candidate {
    int dr, dc, ring;
    long long length2;
  };
  std::vector<Candidate> found;
  const int pair_reach = std::min(2 * reach, rows - 1);
  for (int a = -pair_reach; a <= pair_reach; ++a) {
    int width = -1;
    for (int dr = std::max(-reach, a - reach); dr <= std::min(reach, a + reach); ++dr)
      width = std::max(width, half_width(dr) + half_width(a - dr));
    width = std::min(width, cols - 1);
    for (int b = -width; b <= width; ++b) {
      if (a == 0 && b == 0) continue;
      found.push_back(
          {a, b, std::max(std::abs(a), std::abs(b)), static_cast<long long>(a) * a + static_cast<long long>(b) * b});
    }
  }
  std::sort(found.begin(), found.end(), [](const Candidate& x, const Candidate& y) {
    if (x.ring != y.ring) return x.ring < y.ring;
    if (x.length2 != y.length2) return x.length2 < y.length2;
    if (x.dr != y.dr) return x.dr > y.dr;  // lower partners first: their lenses reach the ball's unvisited rows
    return x.dc > y.dc;
  });
  for (const Candidate& c : found) {
    s.max_ring = std::max(s.max_ring, c.ring);
    s.partner_rows = std::max(s.partner_rows, std::abs(c.dr));
    s.partner_cols = std::max(s.partner_cols, std::abs(c.dc));
  }
  s.ring_begin.assign(s.max_ring + 2, 0);
  for (const Candidate& c : found) {
    Partner p;
    p.dr = c.dr;
    p.dc = c.dc;
    p.offset = static_cast<std::ptrdiff_t>(c.dr) * cols + c.dc;
    // Same expression shape as the ring bound below, so that rounding keeps threshold_m >= ring_threshold_m.
    p.threshold_m =
        params.eps_m + params.kappa * (cs * std::sqrt(static_cast<double>(c.length2))) + tolerance::kHeightM;
    s.partners.push_back(p);
    s.partner_offset.push_back(p.offset);
    s.partner_threshold_m.push_back(p.threshold_m);
    ++s.ring_begin[c.ring + 1];
  }
  for (int k = 1; k <= s.max_ring + 1; ++k) s.ring_begin[k] += s.ring_begin[k - 1];
  s.ring_threshold_m.assign(s.max_ring + 1, 0.0);
  s.ring_bit.assign(s.max_ring + 1, 0);
  for (int k = 1; k <= s.max_ring; ++k) {
    s.ring_threshold_m[k] = params.eps_m + params.kappa * (cs * static_cast<double>(k));
    s.ring_bit[k] = static_cast<Flags>(1u << ring_group(k, s.max_ring));
  }

  const int words = (bits + 63) / 64;
  const bool bitsets =
      marking == LensMarking::kBitsets ||
      (marking == LensMarking::kAutomatic && s.partners.size() * static_cast<std::size_t>(words) <= kMaxLensTableWords);
  if (bitsets) {
    s.lens_words = words;
    s.lens_bits.assign(s.partners.size() * static_cast<std::size_t>(words), 0);
    for (std::size_t i = 0; i < s.partners.size(); ++i) {
      const Partner& v = s.partners[i];
      std::uint64_t* lens = &s.lens_bits[i * static_cast<std::size_t>(words)];
      for (int dr = -s.ball_reach; dr <= s.ball_reach; ++dr) {
        const int w = s.ball_width[dr + s.ball_reach];
        const int other = half_width(dr - v.dr);
        if (other < 0) continue;
        const int lo = std::max(-w, v.dc - other), hi = std::min(w, v.dc + other);
        for (int dc = lo; dc <= hi; ++dc) {
          const int bit = s.ball_first_bit[dr + s.ball_reach] + dc + w;
          lens[bit >> 6] |= std::uint64_t{1} << (bit & 63);
        }
      }
    }
  }
  return s;
}

inline double max3(double a, double b, double c) {
  const double ab = a < b ? b : a;
  return ab < c ? c : ab;
}

/// out[x] = max of in over [x - 1, x + 1] clipped to the row.
void dilate_row(const double* in, double* out, int n) {
  if (n == 1) {
    out[0] = in[0];
    return;
  }
  out[0] = in[0] < in[1] ? in[1] : in[0];
  for (int x = 1; x + 1 < n; ++x) out[x] = max3(in[x - 1], in[x], in[x + 1]);
  out[n - 1] = in[n - 2] < in[n - 1] ? in[n - 1] : in[n - 2];
}

/// Per cell, the bit of every ring group that may hold a partner q with h(q) - h(r) above its threshold:
/// R_k(r) - h(r) > eps + kappa * cs * k, with R_k the maximum of h over the Chebyshev ring k around r (its cells
/// are at least k cells away). The top and bottom sides of the ring are horizontal window maxima of radius k on
/// rows r -+ k, the left and right sides vertical window maxima on columns c -+ k; both grow by one 3-cell
/// dilation per ring. Strips of rows keep the buffers small.
std::vector<Flags> ring_flags(const Heightmap& h, const Stencil& s) {
  const int rows = h.rows(), cols = h.cols(), rings = s.max_ring;
  std::vector<Flags> flags(static_cast<std::size_t>(h.size()), 0);
  const int strip = std::max(kStripRows, rings);
  const std::size_t buffer = static_cast<std::size_t>(std::min(rows, strip + 2 * rings)) * cols;
  std::vector<double> across(buffer), across_next(buffer), down(buffer), down_next(buffer),
      ring(static_cast<std::size_t>(cols));
  const double* heights = h.data();
  for (int y0 = 0; y0 < rows; y0 += strip) {
    const int y1 = std::min(rows, y0 + strip);
    const int b0 = std::max(0, y0 - rings), b1 = std::min(rows, y1 + rings);
    auto row_of = [&](std::vector<double>& buf, int y) { return buf.data() + static_cast<std::size_t>(y - b0) * cols; };
    std::copy(heights + static_cast<std::size_t>(b0) * cols, heights + static_cast<std::size_t>(b1) * cols,
              across.data());
    std::copy(across.begin(), across.begin() + static_cast<std::ptrdiff_t>(b1 - b0) * cols, down.begin());
    for (int k = 1; k <= rings; ++k) {
      // across: maximum over columns [x - k, x + k] of every buffered row.
      for (int y = b0; y < b1; ++y) dilate_row(row_of(across, y), row_of(across_next, y), cols);
      across.swap(across_next);
      // down: maximum over rows [y - k, y + k], needed on the strip only; the band shrinks by a row per ring.
      const int lo = std::max(b0, y0 - (rings - k)), hi = std::min(b1, y1 + (rings - k));
      for (int y = lo; y < hi; ++y) {
        const double* mid = row_of(down, y);
        const double* up = y > b0 ? mid - cols : mid;
        const double* below = y + 1 < b1 ? mid + cols : mid;
        double* out = row_of(down_next, y);
        for (int x = 0; x < cols; ++x) out[x] = max3(up[x], mid[x], below[x]);
      }
      down.swap(down_next);
      const double threshold = s.ring_threshold_m[k];
      const Flags bit = s.ring_bit[k];
      for (int y = y0; y < y1; ++y) {
        const double* top = y - k >= 0 ? row_of(across, y - k) : nullptr;
        const double* bottom = y + k < rows ? row_of(across, y + k) : nullptr;
        if (top != nullptr && bottom != nullptr)
          for (int x = 0; x < cols; ++x) ring[x] = top[x] < bottom[x] ? bottom[x] : top[x];
        else if (top != nullptr || bottom != nullptr)
          std::copy(top != nullptr ? top : bottom, (top != nullptr ? top : bottom) + cols, ring.begin());
        else
          std::fill(ring.begin(), ring.end(), -std::numeric_limits<double>::infinity());
        const double* sides = row_of(down, y);
        for (int x = k; x < cols; ++x) ring[x] = ring[x] < sides[x - k] ? sides[x - k] : ring[x];
        for (int x = 0; x + k < cols; ++x) ring[x] = ring[x] < sides[x + k] ? sides[x + k] : ring[x];
        const double* hr = heights + static_cast<std::size_t>(y) * cols;
        Flags* f = flags.data() + static_cast<std::size_t>(y) * cols;
        for (int x = 0; x < cols; ++x) f[x] = static_cast<Flags>(f[x] | (ring[x] - hr[x] > threshold ? bit : 0));
      }
    }
  }
  return flags;
}

/// True when one of the n mask bytes at p is non-zero.
bool any_set(const std::uint8_t* p, int n) {
  if (n >= 8) {
    // 8-byte words, the last one overlapping its predecessor.
    std::uint64_t word, last;
    for (int x = 0; x + 8 < n; x += 8) {
      std::memcpy(&word, p + x, sizeof word);
      if (word != 0) return true;
    }
    std::memcpy(&last, p + n - 8, sizeof last);
    return last != 0;
  }
  if (n >= 4) {
    std::uint32_t head, tail;
    std::memcpy(&head, p, sizeof head);
    std::memcpy(&tail, p + n - 4, sizeof tail);
    return (head | tail) != 0;
  }
  for (int x = 0; x < n; ++x)
    if (p[x] != 0) return true;
  return false;
}

/// Tiles of 2^kTileShift cells squared, 1 when the tile held an occupiable cell at build time. Cells are only
/// ever cleared, so a tile at 0 stays empty: a ball covered by empty tiles has nothing left to clear.
class TileSummary {
 public:
  TileSummary() = default;
  explicit TileSummary(const CellMask& occupiable)
      : rows_((static_cast<int>(occupiable.rows()) + (1 << kTileShift) - 1) >> kTileShift),
        cols_((static_cast<int>(occupiable.cols()) + (1 << kTileShift) - 1) >> kTileShift),
        tiles_(static_cast<std::size_t>(rows_) * cols_, 0) {
    const int cols = static_cast<int>(occupiable.cols());
    for (Eigen::Index y = 0; y < occupiable.rows(); ++y) {
      const std::uint8_t* cells = occupiable.data() + y * cols;
      std::uint8_t* tiles = tiles_.data() + static_cast<std::size_t>(y >> kTileShift) * cols_;
      for (int x = 0; x < cols; x += 1 << kTileShift)
        tiles[x >> kTileShift] |= any_set(cells + x, std::min(1 << kTileShift, cols - x)) ? 1 : 0;
    }
  }
  /// True when a tile meeting rows [r0, r1] x cols [c0, c1] (on the grid) held an occupiable cell.
  bool any(int r0, int r1, int c0, int c1) const {
    for (int ty = r0 >> kTileShift; ty <= r1 >> kTileShift; ++ty)
      for (int tx = c0 >> kTileShift; tx <= c1 >> kTileShift; ++tx)
        if (tiles_[static_cast<std::size_t>(ty) * cols_ + tx] != 0) return true;
    return false;
  }

 private:
  int rows_ = 0, cols_ = 0;
  std::vector<std::uint8_t> tiles_;
};

/// Bit i set when p[i] is 1, for the n <= 8 mask bytes (each 0 or 1) at p.
inline std::uint64_t pack_mask_bytes(const std::uint8_t* p, int n) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  std::uint64_t word = 0;
  if (n == 8)
    std::memcpy(&word, p, 8);
  else
    std::memcpy(&word, p, static_cast<std::size_t>(n));
  return (word * 0x0102040810204080ULL) >> 56;  // byte i (0 or 1) lands on bit 56 + i
#else
  std::uint64_t bits = 0;
  for (int i = 0; i < n; ++i) bits |= static_cast<std::uint64_t>(p[i] != 0) << i;
  return bits;
#endif
}

/// Clears the lenses of violating pairs, one candidate low end at a time.
class LensClearer {
 public:
  LensClearer(const Heightmap& h, const Stencil& s, CellMask& occupiable)
      : s_(s),
        rows_(h.rows()),
        cols_(h.cols()),
        heights_(h.data()),
        occ_(occupiable.data()),
        unmarked_(static_cast<std::size_t>(s.lens_words)) {}

  /// From now on, skip candidates whose ball lies in tiles that are empty now.
  void summarise_tiles(const CellMask& occupiable) {
    tiles_ = TileSummary(occupiable);
    use_tiles_ = true;
  }

  /// Clears the lenses of every violating pair with low end (row, col) and a partner in a ring of [ring_lo,
  /// ring_hi] whose group bit is in `groups`.
  void run(std::ptrdiff_t index, int row, int col, Flags groups, int ring_lo, int ring_hi) {
    if (use_tiles_ && !tiles_.any(std::max(row - s_.ball_reach, 0), std::min(row + s_.ball_reach, rows_ - 1),
                                  std::max(col - s_.ball_width[s_.ball_reach], 0),
                                  std::min(col + s_.ball_width[s_.ball_reach], cols_ - 1)))
      return;
    const bool interior = row >= s_.partner_rows && row + s_.partner_rows < rows_ && col >= s_.partner_cols &&
                          col + s_.partner_cols < cols_;
    if (s_.lens_words > 0) {
      if (interior)
        run_bitsets<true>(index, row, col, groups, ring_lo, ring_hi);
      else
        run_bitsets<false>(index, row, col, groups, ring_lo, ring_hi);
    } else {
      if (interior)
        run_spans<true>(index, row, col, groups, ring_lo, ring_hi);
      else
        run_spans<false>(index, row, col, groups, ring_lo, ring_hi);
    }
  }

 private:
  /// True when (row, col) + v is on the grid and h there exceeds `low` by more than v's threshold.
  template <bool kInterior>
  bool violates(std::ptrdiff_t index, int row, int col, double low, const Partner& v) const {
    if (!kInterior && (static_cast<unsigned>(row + v.dr) >= static_cast<unsigned>(rows_) ||
                       static_cast<unsigned>(col + v.dc) >= static_cast<unsigned>(cols_)))
      return false;
    return heights_[index + v.offset] - low > v.threshold_m;
  }

  /// Fills unmarked_ with the ball cells around (row, col) that are still occupiable; false when there is none.
  bool gather_ball(int row, int col) {
    std::fill(unmarked_.begin(), unmarked_.end(), 0);
    std::uint64_t any = 0;
    for (int dr = -s_.ball_reach; dr <= s_.ball_reach; ++dr) {
      const int y = row + dr;
      if (y < 0 || y >= rows_) continue;
      const int w = s_.ball_width[dr + s_.ball_reach];
      const int c0 = std::max(col - w, 0), c1 = std::min(col + w, cols_ - 1);
      const std::uint8_t* cells = occ_ + static_cast<std::ptrdiff_t>(y) * cols_;
      if (!any_set(cells + c0, c1 - c0 + 1)) continue;
      const int first = s_.ball_first_bit[dr + s_.ball_reach] + (c0 - (col - w)), n = c1 - c0 + 1;
      for (int x = 0; x < n; x += 8) {
        const std::uint64_t bits = pack_mask_bytes(cells + c0 + x, std::min(8, n - x));
        if (bits == 0) continue;
        any |= bits;
        const int at = first + x, shift = at & 63;
        unmarked_[at >> 6] |= bits << shift;
        // Bits past this word belong to the next one; a set bit is a ball cell, so that word exists.
        const std::uint64_t spill = shift > 56 ? bits >> (64 - shift) : 0;
        if (spill != 0) unmarked_[(at >> 6) + 1] |= spill;
      }
    }
    return any != 0;
  }

  /// First partner in [i, end) of a candidate away from the edges whose pair violates, or end. Violations are
  /// rare among the partners of flagged rings, so partners are tested four at a time.
  int next_violation(std::ptrdiff_t index, double low, int i, int end) const {
    const double* base = heights_ + index;
    const std::ptrdiff_t* offset = s_.partner_offset.data();
    const double* threshold = s_.partner_threshold_m.data();
    for (; i + 4 <= end; i += 4) {
      const bool a = base[offset[i]] - low > threshold[i], b = base[offset[i + 1]] - low > threshold[i + 1];
      const bool c = base[offset[i + 2]] - low > threshold[i + 2], d = base[offset[i + 3]] - low > threshold[i + 3];
      if (a | b | c | d) break;
    }
    for (; i < end; ++i)
      if (base[offset[i]] - low > threshold[i]) return i;
    return end;
  }

  template <bool kInterior>
  void run_bitsets(std::ptrdiff_t index, int row, int col, Flags groups, int ring_lo, int ring_hi) {
    // With many partners to check, first make sure there is something left to clear.
    if (use_tiles_ && !ball_has_occupiable(row, col)) return;
    const double low = heights_[index];
    const int words = s_.lens_words;
    bool gathered = false;  // most candidates come from loose bounds and have no violating partner at all
    for (int k = ring_lo; k <= ring_hi; ++k) {
      if ((groups & s_.ring_bit[k]) == 0) continue;
      const int end = s_.ring_begin[k + 1];
      for (int i = s_.ring_begin[k]; i < end; ++i) {
        if (kInterior) {
          i = next_violation(index, low, i, end);
          if (i == end) break;
        } else if (!violates<false>(index, row, col, low, s_.partners[i])) {
          continue;
        }
        if (!gathered) {
          if (!gather_ball(row, col)) return;
          gathered = true;
        }
        const std::uint64_t* lens = &s_.lens_bits[static_cast<std::size_t>(i) * words];
        bool left = false;
        for (int w = 0; w < words; ++w) {
          std::uint64_t hit = unmarked_[w] & lens[w];
          if (hit != 0) {
            unmarked_[w] &= ~hit;
            do {
              const int bit = w * 64 + __builtin_ctzll(hit);
              occ_[index + s_.ball_offset[bit]] = 0;
              hit &= hit - 1;
            } while (hit != 0);
          }
          left |= unmarked_[w] != 0;
        }
        if (!left) return;
      }
    }
  }

  bool ball_has_occupiable(int row, int col) const {
    for (int dr = -s_.ball_reach; dr <= s_.ball_reach; ++dr) {
      const int y = row + dr;
      if (y < 0 || y >= rows_) continue;
      const int w = s_.ball_width[dr + s_.ball_reach];
      const int c0 = std::max(col - w, 0), c1 = std::min(col + w, cols_ - 1);
      if (any_set(occ_ + static_cast<std::ptrdiff_t>(y) * cols_ + c0, c1 - c0 + 1)) return true;
    }
    return false;
  }

  void clear_lens_spans(int row, int col, const Partner& v) {
    const int first = std::max(-s_.ball_reach, v.dr - s_.reach), last = std::min(s_.ball_reach, v.dr + s_.reach);
    for (int dr = first; dr <= last; ++dr) {
      const int y = row + dr;
      if (y < 0 || y >= rows_) continue;
      const int w = s_.half_width[dr + s_.reach], other = s_.half_width[dr - v.dr + s_.reach];
      if (w < 0 || other < 0) continue;
      const int c0 = std::max({0, col - w, col + v.dc - other});
      const int c1 = std::min({cols_ - 1, col + w, col + v.dc + other});
      if (c0 <= c1)
        std::memset(occ_ + static_cast<std::ptrdiff_t>(y) * cols_ + c0, 0, static_cast<std::size_t>(c1 - c0 + 1));
    }
  }

  template <bool kInterior>
  void run_spans(std::ptrdiff_t index, int row, int col, Flags groups, int ring_lo, int ring_hi) {
    if (!ball_has_occupiable(row, col)) return;
    const double low = heights_[index];
    int cleared = 0;
    for (int k = ring_lo; k <= ring_hi; ++k) {
      if ((groups & s_.ring_bit[k]) == 0) continue;
      for (int i = s_.ring_begin[k]; i < s_.ring_begin[k + 1]; ++i) {
        const Partner& v = s_.partners[i];
        if (!violates<kInterior>(index, row, col, low, v)) continue;
        clear_lens_spans(row, col, v);
        if (++cleared % kSpanChecksEvery == 0 && !ball_has_occupiable(row, col)) return;
      }
    }
  }

  const Stencil& s_;
  int rows_, cols_;
  const double* heights_;
  std::uint8_t* occ_;
  std::vector<std::uint64_t> unmarked_;
  TileSummary tiles_;
  bool use_tiles_ = false;
};

}  // namespace

CellMask occupiable_mask(const Heightmap& h, const NavigabilityParams& params, LensMarking marking) {
  const int rows = h.rows(), cols = h.cols();
  CellMask occupiable = CellMask::Ones(rows, cols);
  if (h.size() == 0) return occupiable;
  const Stencil s = build_stencil(params, rows, cols, h.cell_size_m(), marking);
  if (s.max_ring == 0) return occupiable;  // the ball is one cell (or the grid is): no pairs

  const std::vector<Flags> flags = ring_flags(h, s);
  LensClearer clearer(h, s, occupiable);
  // Pass one: the innermost ring group, whose lenses cover most of the ball; on rough ground it clears
  // nearly everything, so pass two mostly finds balls with nothing left to clear.
  const Flags inner = s.ring_bit[1];
  int inner_last = 1;
  while (inner_last < s.max_ring && s.ring_bit[inner_last + 1] == inner) ++inner_last;
  const Flags outer = static_cast<Flags>(~inner);
  for (int pass = 0; pass < 2; ++pass) {
    const Flags mask = pass == 0 ? inner : outer;
    const int ring_lo = pass == 0 ? 1 : inner_last + 1, ring_hi = pass == 0 ? inner_last : s.max_ring;
    if (ring_lo > ring_hi) continue;
    if (pass == 1) clearer.summarise_tiles(occupiable);
    std::ptrdiff_t index = 0;
    for (int row = 0; row < rows; ++row)
      for (int col = 0; col < cols; ++col, ++index) {
        const Flags groups = static_cast<Flags>(flags[static_cast<std::size_t>(index)] & mask);
        if (groups != 0) clearer.run(index, row, col, groups, ring_lo, ring_hi);
      }
  }
  return occupiable;
}

}  // namespace marsala::detail
