#include "marsala/core/detail/mars_search.hpp"

#include "marsala/core/detail/mars_pair.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace marsala::detail {
namespace {

// Distances below are floored at the local radius: every source closer than that has already
// been applied exactly by apply_local_sources().
constexpr long long kFloor2 = kLocalRadius2 + 1;

constexpr int kTargets = kBlock * kBlock;
constexpr int kHalf = kBlock / 2;
// Leaves whose heights a search keeps at once (BlockSearch::leaf_heights()): every leaf of a window, a band of
// leaves a few blocks high on a large grid [leaves].
constexpr std::int64_t kLeafCache = 1024;

// Searches the tree for one kBlock x kBlock block of targets at a time, depth first, children in
// decreasing order of their upper bound; a node is dropped for a target as soon as one of its
// bounds is <= the target's current value + tol. A node's bounds are tested on all 64 targets of
// the block at once, two at a time and without branches; the mask of live targets then selects
// which targets go on.
class BlockSearch {
 public:
  BlockSearch(const Problem& pb, const SourceTree& tree, double* lower, const std::uint64_t* wanted)
      : pb_(pb),
        wanted_(wanted),
        tree_(tree),
        lower_(lower),
        kcs2_(pb.kcs * pb.kcs),
        leaf_cache_(static_cast<std::size_t>(
            std::min(kLeafCache, static_cast<std::int64_t>(tree.width(0)) * tree.height(0)))) {
    for (int t = 0; t < kTargets; ++t) {
      local_r_[t] = t / kBlock;
      local_c_[t] = t % kBlock;
    }
  }

  void run() {
    for (int bi = 0; bi < tree_.height(0); ++bi)
      for (int bj = 0; bj < tree_.width(0); ++bj) search_block(bi, bj);
  }

 private:
  void search_block(int bi, int bj) {
    const std::uint64_t wanted =
        wanted_ ? wanted_[static_cast<std::size_t>(bi) * tree_.width(0) + bj] : ~std::uint64_t{0};
    if (!wanted) return;
    r0_ = bi * kBlock;
    c0_ = bj * kBlock;
    r1_ = std::min(pb_.rows, r0_ + kBlock) - 1;
    c1_ = std::min(pb_.cols, c0_ + kBlock) - 1;
    block_rows_ = r1_ - r0_ + 1;
    block_pair_cols_ = (c1_ - c0_ + 2) / 2 * 2;
    whole_block_ = block_rows_ == kBlock && block_pair_cols_ == kBlock;
    std::uint64_t targets = 0;
    min_limit_ = kInf;
    max_limit_ = -kInf;
    for (int t = 0; t < kTargets; ++t) {
      tr_[t] = r0_ + local_r_[t];
      tc_[t] = c0_ + local_c_[t];
      limit_[t] = kInf;  // off the grid: every bound is below it
    }
    for (int r = r0_; r <= r1_; ++r)
      for (int c = c0_; c <= c1_; ++c) {
        const int t = (r - r0_) * kBlock + (c - c0_);
        if (!(wanted >> t & 1)) continue;  // as off the grid
        targets |= std::uint64_t{1} << t;
        limit_[t] = lower_[static_cast<std::int64_t>(r) * pb_.cols + c] + pb_.tol;
        min_limit_ = std::min(min_limit_, limit_[t]);
        max_limit_ = std::max(max_limit_, limit_[t]);
      }
    if (targets) visit(tree_.top_level(), 0, 0, targets);
  }

  // Squared distance from the target block to a node's box, floored [cells^2].
  long long block_distance2(const SourceNode& nd) const {
    const long long dr = std::max({0, nd.r0 - r1_, r0_ - nd.r1}), dc = std::max({0, nd.c0 - c1_, c0_ - nd.c1});
    return std::max(dr * dr + dc * dc, kFloor2);
  }

  // OR of test(t) << t over the pairs of targets t, t + 1 of the block: all of them in a block inside the grid
  // (skipping rows without live targets mispredicted more branches than it saved), only the rows and column pairs
  // on the grid in a block cut by its edge (a small window's last row and column of blocks hold 1 of 8).
  template <class Test>
  std::uint64_t pairs_where(Test test) const {
    std::uint64_t out = 0;
    if (whole_block_) {
      for (int t = 0; t < kTargets; t += 2) out |= std::uint64_t{test(t)} << t;
      return out;
    }
    for (int k = 0; k < block_rows_; ++k)
      for (int t = k * kBlock; t < k * kBlock + block_pair_cols_; t += 2) out |= std::uint64_t{test(t)} << t;
    return out;
  }

  // True when one of the node's bounds is <= min_limit_ on the whole block (then it is so at every
  // target, whose limit is >= min_limit_): the tests of live_targets() on the block's box, for a
  // target distance of `d2` [cells^2] (block_distance2()).
  bool block_pruned(const SourceNode& nd, long long d2) const {
    const double fr[2] = {static_cast<double>(r0_), static_cast<double>(r1_)};
    const double fc[2] = {static_cast<double>(c0_), static_cast<double>(c1_)};
    for (const Shape& s : nd.shapes) {
      const double z = s.m - min_limit_;
      switch (s.kind) {
        case Shape::Kind::kNone: return false;
        case Shape::Kind::kPlane: {
          const double y = s.m + std::max(s.ar * (fr[0] - s.r), s.ar * (fr[1] - s.r)) +
                           std::max(s.ac * (fc[0] - s.c), s.ac * (fc[1] - s.c)) - min_limit_;
          if (y <= 0 || y * y <= s.deficit2 * static_cast<double>(d2)) return true;
          break;
        }
        case Shape::Kind::kCone: {
          const double er = std::max({0.0, fr[0] - s.r, s.r - fr[1]}), ec = std::max({0.0, fc[0] - s.c, s.c - fc[1]});
          if (z <= 0 || z * z <= kcs2_ * (er * er + ec * ec)) return true;
          break;
        }
        case Shape::Kind::kBowl: {
          const double er = std::max(std::abs(fr[0] - s.r), std::abs(fr[1] - s.r));
          const double ec = std::max(std::abs(fc[0] - s.c), std::abs(fc[1] - s.c));
          if (z <= 0 && z * z >= kcs2_ * (er * er + ec * ec)) return true;
          break;
        }
      }
    }
    return false;
  }

  // Of `targets`, those at which some source of the node may exceed the limit: where no bound is
  // <= the limit (max h - kcs d, then each shape of the node; Shape documents them).
  std::uint64_t live_targets(const SourceNode& nd, std::uint64_t targets) {
    alignas(16) double dr2[kBlock], dc2[kBlock];
    for (int k = 0; k < kBlock; ++k) {
      const long long r = r0_ + k, c = c0_ + k;
      const long long dr = std::max({0LL, nd.r0 - r, r - nd.r1}), dc = std::max({0LL, nd.c0 - c, c - nd.c1});
      dr2[k] = static_cast<double>(dr * dr);
      dc2[k] = static_cast<double>(dc * dc);
    }
    const Pair floor2 = {static_cast<double>(kFloor2), static_cast<double>(kFloor2)};
    for (int k = 0; k < kBlock; ++k)
      for (int p = 0; p < kBlock; p += 2) store(d2_ + k * kBlock + p, max(dr2[k] + load(dc2 + p), floor2));
    const Pair zero = {0.0, 0.0};
    const double kcs2 = kcs2_, max_h = nd.max_h;
    // When the height bound clears the block's largest limit at its farthest target it clears every target's.
    const double far2 = std::max(*std::max_element(dr2, dr2 + kBlock) + *std::max_element(dc2, dc2 + kBlock),
                                 static_cast<double>(kFloor2));
    const double x_all = max_h - max_limit_;
    std::uint64_t live = targets;
    if (!(x_all > 0 && x_all * x_all > kcs2 * far2))
      live &= pairs_where([&](int t) {
        const Pair x = max(max_h - load(limit_ + t), zero);
        return greater(x * x, kcs2 * load(d2_ + t));
      });
    for (const Shape& s : nd.shapes) {
      if (!live) break;
      const double m = s.m, sr = s.r, sc = s.c;
      switch (s.kind) {
        case Shape::Kind::kNone: return live;
        case Shape::Kind::kPlane: {
          const double ar = s.ar, ac = s.ac, deficit2 = s.deficit2;
          live &= pairs_where([&](int t) {
            const Pair y = max(m + ar * (load(tr_ + t) - sr) + ac * (load(tc_ + t) - sc) - load(limit_ + t), zero);
            return greater(y * y, deficit2 * load(d2_ + t));
          });
          break;
        }
        case Shape::Kind::kCone: {
          live &= pairs_where([&](int t) {
            const Pair z = max(m - load(limit_ + t), zero), er = load(tr_ + t) - sr, ec = load(tc_ + t) - sc;
            return greater(z * z, kcs2 * (er * er + ec * ec));
          });
          break;
        }
        case Shape::Kind::kBowl: {
          live &= pairs_where([&](int t) {
            const Pair z = m - load(limit_ + t), er = load(tr_ + t) - sr, ec = load(tc_ + t) - sc;
            return greater(z, zero) | greater(kcs2 * (er * er + ec * ec), z * z);
          });
          break;
        }
      }
    }
    return live;
  }

  void visit(int level, int i, int j, std::uint64_t targets) {
    const SourceNode& nd = tree_.node(level, i, j);
    if (nd.empty()) return;
    const double x = nd.max_h - min_limit_;
    const long long d2 = block_distance2(nd);
    if (x <= 0 || x * x <= kcs2_ * static_cast<double>(d2) || block_pruned(nd, d2)) return;
    const std::uint64_t keep = live_targets(nd, targets);
    if (!keep) return;
    if (level == 0) {
      evaluate_leaf(i, j, keep);
      return;
    }
    struct Child {
      int i, j;
      double bound;
    } kids[4];
    int n = 0;
    const int below = level - 1;
    for (int di = 0; di < 2; ++di)
      for (int dj = 0; dj < 2; ++dj) {
        const int ci = 2 * i + di, cj = 2 * j + dj;
        if (ci >= tree_.height(below) || cj >= tree_.width(below)) continue;
        const SourceNode& kid = tree_.node(below, ci, cj);
        if (kid.empty()) continue;
        kids[n++] = {ci, cj, kid.max_h - pb_.kcs * std::sqrt(static_cast<double>(block_distance2(kid)))};
      }
    // Most promising first (insertion sort of <= 4): a better value found early prunes the rest sooner.
    for (int k = 1; k < n; ++k)
      for (int m = k; m > 0 && kids[m].bound > kids[m - 1].bound; --m) std::swap(kids[m], kids[m - 1]);
    for (int k = 0; k < n; ++k) visit(below, kids[k].i, kids[k].j, keep);
  }

  // A leaf's heights for evaluate_leaf(): its sources' heights by bit (-inf elsewhere) and the highest of each 4 x 4
  // quarter [m]. Neighbouring blocks read the same leaves, so the last ones read are kept (direct-mapped by index).
  struct LeafHeights {
    std::int64_t leaf = -1;
    double top[4];
    alignas(16) double hs[kTargets];
  };

  const LeafHeights& leaf_heights(int i, int j) {
    const std::int64_t leaf = static_cast<std::int64_t>(i) * tree_.width(0) + j;
    LeafHeights& out = leaf_cache_[static_cast<std::size_t>(leaf % static_cast<std::int64_t>(leaf_cache_.size()))];
    if (out.leaf == leaf) return out;
    out.leaf = leaf;
    const std::uint64_t sources = tree_.leaf_mask(i, j);
    const int sr0 = i * kBlock, sc0 = j * kBlock;
    for (int s = 0; s < kTargets; ++s) {
      const int sr = sr0 + s / kBlock, sc = sc0 + s % kBlock;
      out.hs[s] = sources >> s & 1 ? pb_.h[static_cast<std::int64_t>(sr) * pb_.cols + sc] : -kInf;
    }
    for (int q = 0; q < 4; ++q) {
      const int qr = q / 2 * kHalf, qc = q % 2 * kHalf;
      double top = -kInf;
      for (int k = qr; k < qr + kHalf; ++k)
        for (int c = qc; c < qc + kHalf; ++c) top = std::max(top, out.hs[k * kBlock + c]);
      out.top[q] = top;
    }
    return out;
  }

  // Applies the leaf's sources to the targets. Each 4 x 4 quarter of the leaf is first bounded, at every target, by
  // its highest source at its box's floored distance (all targets two at a time: a target's limit changes only when
  // its own sources are applied); at each target the sources of the quarters left are then checked two at a time
  // without branches (non-sources at -inf) for one that beats the target's limit, and only then are the leaf's
  // sources applied one by one in bit order, each against the limit as it rises.
  void evaluate_leaf(int i, int j, std::uint64_t targets) {
    const std::uint64_t sources = tree_.leaf_mask(i, j);
    const int sr0 = i * kBlock, sc0 = j * kBlock;
    const LeafHeights& leaf = leaf_heights(i, j);
    const double* hs = leaf.hs;
    const Pair zero = {0.0, 0.0};
    const double kcs2 = kcs2_, floor2 = static_cast<double>(kFloor2);
    // Squared distances from each target row and column to the quarters' boxes: rows 0..3 (top) and 4..7 (bottom),
    // columns 0..3 (left) and 4..7 (right) of the leaf.
    double near2[2][kBlock];
    alignas(16) double across2[2][kBlock];
    for (int k = 0; k < kBlock; ++k) {
      const double er = tr_[k * kBlock] - sr0, ec = tc_[k] - sc0;
      const double dr_top = std::max({0.0, -er, er - (kHalf - 1)});
      const double dr_bottom = std::max({0.0, kHalf - er, er - (kBlock - 1)});
      const double dc_left = std::max({0.0, -ec, ec - (kHalf - 1)});
      const double dc_right = std::max({0.0, kHalf - ec, ec - (kBlock - 1)});
      near2[0][k] = dr_top * dr_top;
      near2[1][k] = dr_bottom * dr_bottom;
      across2[0][k] = dc_left * dc_left;
      across2[1][k] = dc_right * dc_right;
    }
    const Pair floor2s = {floor2, floor2};
    std::uint64_t in_quarter[4];
    for (int q = 0; q < 4; ++q) {
      const double top = leaf.top[q];
      const double* row2 = near2[q / 2];
      const double* col2 = across2[q % 2];
      in_quarter[q] = targets & pairs_where([&](int t) {
        const Pair x = top - load(limit_ + t);
        const Pair d2 = max(row2[t / kBlock] + load(col2 + t % kBlock), floor2s);
        return greater(x, zero) & greater(x * x, kcs2 * d2);
      });
    }
    for (std::uint64_t tb = in_quarter[0] | in_quarter[1] | in_quarter[2] | in_quarter[3]; tb; tb &= tb - 1) {
      const int t = __builtin_ctzll(tb);
      const double limit = limit_[t], er = tr_[t] - sr0, ec = tc_[t] - sc0;
      unsigned quarters = 0;
      for (int q = 0; q < 4; ++q) quarters |= static_cast<unsigned>(in_quarter[q] >> t & 1) << q;
      bool any = false;
      for (; quarters && !any; quarters &= quarters - 1) {
        const int q = __builtin_ctz(quarters), qr = q / 2 * kHalf, qc = q % 2 * kHalf;
        // max(h - limit, 0)^2 > kcs^2 d2 exactly when h - limit > 0 and (h - limit)^2 > kcs^2 d2, apply_leaf()'s test.
        const Pair dc_a = ec - load(local_c_ + qc), dc_b = ec - load(local_c_ + qc + 2);
        const Pair dc2_a = dc_a * dc_a, dc2_b = dc_b * dc_b;
        Pair beats = zero;
        for (int k = qr; k < qr + kHalf; ++k) {
          const double dr = er - k, dr2 = dr * dr;
          const Pair y_a = max(load(hs + k * kBlock + qc) - limit, zero);
          const Pair y_b = max(load(hs + k * kBlock + qc + 2) - limit, zero);
          beats = either(beats, either(greater_mask(y_a * y_a, kcs2 * (dr2 + dc2_a)),
                                       greater_mask(y_b * y_b, kcs2 * (dr2 + dc2_b))));
        }
        any = any_set(beats);
      }
      if (any) apply_leaf(i, j, sources, t);
    }
  }

  void apply_leaf(int i, int j, std::uint64_t sources, int t) {
    const int r = r0_ + t / kBlock, c = c0_ + t % kBlock;
    double& out = lower_[static_cast<std::int64_t>(r) * pb_.cols + c];
    for (std::uint64_t sb = sources; sb; sb &= sb - 1) {
      const int s = __builtin_ctzll(sb);
      const int sr = i * kBlock + s / kBlock, sc = j * kBlock + s % kBlock;
      const double hs = pb_.h[static_cast<std::int64_t>(sr) * pb_.cols + sc];
      const double x = hs - limit_[t];
      if (x <= 0) continue;
      const long long dr = r - sr, dc = c - sc, d2 = dr * dr + dc * dc;
      if (d2 <= kLocalRadius2 || x * x <= kcs2_ * static_cast<double>(d2)) continue;
      const double v = cone_value(hs, pb_.kcs, d2);
      if (v > out) {
        out = v;
        limit_[t] = v + pb_.tol;
        max_limit_ = std::max(max_limit_, limit_[t]);
      }
    }
  }

  const Problem& pb_;
  const std::uint64_t* wanted_;  // targets searched per block; null: all
  const SourceTree& tree_;
  double* lower_;
  double kcs2_;
  std::vector<LeafHeights> leaf_cache_;
  int r0_ = 0, r1_ = 0, c0_ = 0, c1_ = 0;    // target block [cells]
  int block_rows_ = kBlock;                  // rows of the block on the grid
  int block_pair_cols_ = kBlock;             // its columns on the grid, rounded up to pairs
  bool whole_block_ = true;                  // the block lies inside the grid
  alignas(16) double local_r_[kTargets];     // row of bit t within a block or leaf [cells]
  alignas(16) double local_c_[kTargets];     // column of bit t within a block or leaf [cells]
  alignas(16) double tr_[kTargets] = {};     // row of each target [cells]
  alignas(16) double tc_[kTargets] = {};     // column of each target [cells]
  alignas(16) double limit_[kTargets] = {};  // current value + tol per target; +inf off the grid [m]
  alignas(16) double d2_[kTargets] = {};     // floored squared distance of each target to the node [cells^2]
  double min_limit_ = 0;                     // min of limit_ when the block started [m]
  double max_limit_ = 0;                     // max of limit_ over the block's targets on the grid [m]
};

}  // namespace

void search_sources(const Problem& pb, const SourceTree& tree, double* lower, const std::uint64_t* wanted) {
  BlockSearch(pb, tree, lower, wanted).run();
}

}  // namespace marsala::detail
