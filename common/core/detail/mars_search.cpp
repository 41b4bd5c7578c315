#include "marsala/core/detail/mars_search.hpp"

#include <algorithm>
#include <cstdint>

namespace marsala::detail {
namespace {

// Distances below are floored at the local radius: every source closer than that has already
// been applied exactly by apply_local_sources().
constexpr long long kFloor2 = kLocalRadius2 + 1;

// Searches the tree for one kBlock x kBlock block of targets at a time, depth first, children in
// decreasing order of their upper bound; a node is dropped for a target as soon as one of its
// bounds is <= the target's current value + tol.
class BlockSearch {
 public:
  BlockSearch(const Problem& pb, const SourceTree& tree, double* lower)
      : pb_(pb), tree_(tree), lower_(lower), kcs2_(pb.kcs * pb.kcs) {}

  void run() {
    for (int bi = 0; bi < tree_.height(0); ++bi)
      for (int bj = 0; bj < tree_.width(0); ++bj) search_block(bi, bj);
  }

 private:
  void search_block(int bi, int bj) {
    r0_ = bi * kBlock;
    c0_ = bj * kBlock;
    r1_ = std::min(pb_.rows, r0_ + kBlock) - 1;
    c1_ = std::min(pb_.cols, c0_ + kBlock) - 1;
    std::uint64_t targets = 0;
    min_limit_ = kInf;
    for (int r = r0_; r <= r1_; ++r)
      for (int c = c0_; c <= c1_; ++c) {
        const int t = (r - r0_) * kBlock + (c - c0_);
        targets |= std::uint64_t{1} << t;
        limit_[t] = lower_[static_cast<std::int64_t>(r) * pb_.cols + c] + pb_.tol;
        min_limit_ = std::min(min_limit_, limit_[t]);
      }
    visit(tree_.top_level(), 0, 0, targets);
  }

  // Squared distance from the target block to a node's box, floored [cells^2].
  long long block_distance2(const SourceNode& nd) const {
    const long long dr = std::max({0, nd.r0 - r1_, r0_ - nd.r1}), dc = std::max({0, nd.c0 - c1_, c0_ - nd.c1});
    return std::max(dr * dr + dc * dc, kFloor2);
  }

  // True when no source of the node can exceed `limit` at target (r, c).
  bool pruned(const SourceNode& nd, int r, int c, double limit) const {
    const double x = nd.max_h - limit;
    if (x <= 0) return true;
    const long long dr = std::max({0, nd.r0 - r, r - nd.r1}), dc = std::max({0, nd.c0 - c, c - nd.c1});
    const double d2 = static_cast<double>(std::max(dr * dr + dc * dc, kFloor2));
    if (x * x <= kcs2_ * d2) return true;  // height: max h - kcs d <= limit
    for (const Shape& s : nd.shapes) {
      switch (s.kind) {
        case Shape::Kind::kNone: return false;
        case Shape::Kind::kPlane: {
          const double y = s.m + s.ar * (r - s.r) + s.ac * (c - s.c) - limit;
          if (y <= 0 || y * y <= s.deficit2 * d2) return true;
          break;
        }
        case Shape::Kind::kCone: {
          const double z = s.m - limit, er = r - s.r, ec = c - s.c;
          if (z <= 0 || z * z <= kcs2_ * (er * er + ec * ec)) return true;
          break;
        }
        case Shape::Kind::kBowl: {
          const double z = s.m - limit, er = r - s.r, ec = c - s.c;
          if (z <= 0 && z * z >= kcs2_ * (er * er + ec * ec)) return true;
          break;
        }
      }
    }
    return false;
  }

  void visit(int level, int i, int j, std::uint64_t targets) {
    const SourceNode& nd = tree_.node(level, i, j);
    if (nd.empty()) return;
    const double x = nd.max_h - min_limit_;
    if (x <= 0 || x * x <= kcs2_ * static_cast<double>(block_distance2(nd))) return;
    std::uint64_t keep = 0;
    for (std::uint64_t bits = targets; bits; bits &= bits - 1) {
      const int t = __builtin_ctzll(bits);
      if (!pruned(nd, r0_ + t / kBlock, c0_ + t % kBlock, limit_[t])) keep |= std::uint64_t{1} << t;
    }
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

  void evaluate_leaf(int i, int j, std::uint64_t targets) {
    const std::uint64_t sources = tree_.leaf_mask(i, j);
    for (std::uint64_t tb = targets; tb; tb &= tb - 1) {
      const int t = __builtin_ctzll(tb);
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
        }
      }
    }
  }

  const Problem& pb_;
  const SourceTree& tree_;
  double* lower_;
  double kcs2_;
  int r0_ = 0, r1_ = 0, c0_ = 0, c1_ = 0;  // target block [cells]
  double limit_[kBlock * kBlock] = {};     // current value + tol per target [m]
  double min_limit_ = 0;                   // min of limit_ when the block started [m]
};

}  // namespace

void search_sources(const Problem& pb, const SourceTree& tree, double* lower) { BlockSearch(pb, tree, lower).run(); }

}  // namespace marsala::detail
