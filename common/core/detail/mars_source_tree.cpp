#include "marsala/core/detail/mars_source_tree.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>

namespace marsala::detail {
namespace {

// Node levels up to this one (leaves of 8 cells: nodes of up to 64 x 64 cells) recompute a
// candidate surface exactly over their sources when merging the children's bounds is loose.
constexpr int kExactLevels = 3;

// A cone or bowl fit goes on to its Gauss-Newton steps only when its algebraic start leaves the points within this
// many cells' drop (kcs) of one slope-kappa surface [cells].
constexpr double kFitSpread = 0.25;

// Euclidean length of (a, b): only bounds and fits use it (every bound is taken as a max over the sources or pruned
// against tol, so an ulp here never changes an output), and it costs a fraction of std::hypot's careful rounding.
inline double length(double a, double b) { return std::sqrt(a * a + b * b); }

struct Point {
  double r, c, h;
};

// Centred first and second moments of (row, col, h) over a set of sources.
struct Moments {
  double n = 0, mr = 0, mc = 0, mh = 0;
  double crr = 0, crc = 0, ccc = 0, crh = 0, cch = 0;

  static Moments of(const Point* pts, const int* idx, int n) {
    Moments m;
    m.n = n;
    for (int k = 0; k < n; ++k) {
      m.mr += pts[idx[k]].r;
      m.mc += pts[idx[k]].c;
      m.mh += pts[idx[k]].h;
    }
    m.mr /= n;
    m.mc /= n;
    m.mh /= n;
    for (int k = 0; k < n; ++k) {
      const double r = pts[idx[k]].r - m.mr, c = pts[idx[k]].c - m.mc, h = pts[idx[k]].h - m.mh;
      m.crr += r * r;
      m.crc += r * c;
      m.ccc += c * c;
      m.crh += r * h;
      m.cch += c * h;
    }
    return m;
  }

  void merge(const Moments& o) {
    if (o.n == 0) return;
    if (n == 0) {
      *this = o;
      return;
    }
    const double total = n + o.n, w = n * o.n / total;
    const double dr = o.mr - mr, dc = o.mc - mc, dh = o.mh - mh;
    crr += o.crr + w * dr * dr;
    crc += o.crc + w * dr * dc;
    ccc += o.ccc + w * dc * dc;
    crh += o.crh + w * dr * dh;
    cch += o.cch + w * dc * dh;
    mr += dr * o.n / total;
    mc += dc * o.n / total;
    mh += dh * o.n / total;
    n = total;
  }

  // Least-squares plane through the centroid, slope shrunk to |a| < kcs; m is left to the caller.
  // raw_slope receives |a| before shrinking [m/cell].
  Shape plane(double kcs, double* raw_slope = nullptr) const {
    double ar = 0, ac = 0;
    const double det = crr * ccc - crc * crc, trace = crr + ccc;
    if (n >= 3 && det > 1e-9 * trace * trace) {
      ar = (ccc * crh - crc * cch) / det;
      ac = (crr * cch - crc * crh) / det;
    } else if (trace > 0) {
      // Collinear sources: slope along their line only (minimum-norm least squares).
      const double half_gap = 0.5 * (crr - ccc);
      const double lambda = 0.5 * trace + std::sqrt(half_gap * half_gap + crc * crc);
      double ur = crc, uc = lambda - crr;
      if (ur == 0 && uc == 0) {
        ur = crr >= ccc ? 1 : 0;
        uc = 1 - ur;
      }
      const double norm = length(ur, uc);
      const double slope = (ur * crh + uc * cch) / (norm * lambda);
      ar = slope * ur / norm;
      ac = slope * uc / norm;
    }
    if (!std::isfinite(ar) || !std::isfinite(ac)) ar = ac = 0;
    const double norm = length(ar, ac), limit = kcs * (1.0 - 1e-12);
    if (raw_slope) *raw_slope = norm;
    if (norm > limit) {
      ar *= limit / norm;
      ac *= limit / norm;
    }
    Shape s;
    s.kind = Shape::Kind::kPlane;
    s.r = mr;
    s.c = mc;
    s.ar = ar;
    s.ac = ac;
    const double deficit = kcs - length(ar, ac);
    s.deficit2 = deficit > 0 ? deficit * deficit : 0.0;
    return s;
  }
};

// The quantity whose maximum over a node's sources is Shape::m.
inline double residual(const Shape& s, double kcs, double r, double c, double h) {
  const double dr = r - s.r, dc = c - s.c;
  switch (s.kind) {
    case Shape::Kind::kPlane: return h - s.ar * dr - s.ac * dc;
    case Shape::Kind::kCone: return h + kcs * std::sqrt(dr * dr + dc * dc);
    case Shape::Kind::kBowl: return h - kcs * std::sqrt(dr * dr + dc * dc);
    case Shape::Kind::kNone: break;
  }
  return kInf;
}

// Fits a cone or bowl of slope kcs to the points: algebraic fit of (H - h)^2 = kcs^2 |q - c|^2
// (linear in H, c and kcs^2 |c|^2 - H^2, exact on exact data), then Gauss-Newton steps on
// h + sign kcs |q - c| = H. Returns kNone when degenerate, or when the algebraic fit leaves the
// points further than max_spread [m] from one surface (rough ground: no cone or bowl of slope
// kappa is near it, and the Gauss-Newton steps would cost more than the bound saves). Any result
// is a valid shape once its m is taken over the sources; the fit only decides how tight it is.
Shape fit_apex(const Point* pts, const int* idx, int n, double kcs, double max_spread) {
  Shape s;
  if (n < 5) return s;
  double r0 = 0, c0 = 0, h0 = 0;
  for (int k = 0; k < n; ++k) {
    r0 += pts[idx[k]].r;
    c0 += pts[idx[k]].c;
    h0 += pts[idx[k]].h;
  }
  r0 /= n;
  c0 /= n;
  h0 /= n;
  const double k2 = kcs * kcs;
  const Eigen::Vector4d scale(1.0, 1.0 / (8.0 * kcs), 1.0 / (8.0 * kcs), 1.0);
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  for (int k = 0; k < n; ++k) {
    const double r = pts[idx[k]].r - r0, c = pts[idx[k]].c - c0, h = pts[idx[k]].h - h0;
    const Eigen::Vector4d f = Eigen::Vector4d(2.0 * h, -2.0 * k2 * r, -2.0 * k2 * c, 1.0).cwiseProduct(scale);
    normal += f * f.transpose();
    rhs += f * (h * h - k2 * (r * r + c * c));
  }
  const Eigen::Vector4d theta = normal.ldlt().solve(rhs).cwiseProduct(scale);
  double top = theta(0), cr = theta(1), cc = theta(2);
  if (!theta.allFinite()) return s;
  const double sign = top >= 0 ? 1.0 : -1.0;  // centred heights: a cone's apex lies above them
  double lowest = kInf, highest = -kInf;
  for (int k = 0; k < n; ++k) {
    const double er = cr - (pts[idx[k]].r - r0), ec = cc - (pts[idx[k]].c - c0);
    const double v = pts[idx[k]].h - h0 + sign * kcs * std::sqrt(er * er + ec * ec);
    lowest = std::min(lowest, v);
    highest = std::max(highest, v);
  }
  if (!(highest - lowest <= max_spread)) return s;
  for (int iter = 0; iter < 3; ++iter) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jte = Eigen::Vector3d::Zero();
    for (int k = 0; k < n; ++k) {
      const double er = cr - (pts[idx[k]].r - r0), ec = cc - (pts[idx[k]].c - c0);
      const double dist = std::sqrt(er * er + ec * ec);
      if (dist == 0) continue;
      const Eigen::Vector3d j(sign * kcs * er / dist, sign * kcs * ec / dist, -1.0);
      jtj += j * j.transpose();
      jte += j * (pts[idx[k]].h - h0 + sign * kcs * dist - top);
    }
    const Eigen::Vector3d step = jtj.ldlt().solve(jte);
    if (!step.allFinite()) break;
    cr -= step(0);
    cc -= step(1);
    top -= step(2);
  }
  if (!std::isfinite(cr) || !std::isfinite(cc)) return s;
  s.kind = sign > 0 ? Shape::Kind::kCone : Shape::Kind::kBowl;
  s.r = cr + r0;
  s.c = cc + c0;
  return s;
}

struct Candidate {
  Shape shape;
  double quality = kInf;  // how far the surface may overestimate the sources' values [m]
};

// True when two shapes bound differently enough to be worth keeping both.
bool distinct(const Shape& a, const Shape& b, double kcs) {
  if (a.kind != b.kind) return true;
  if (a.kind == Shape::Kind::kPlane) return length(a.ar - b.ar, a.ac - b.ac) > 1e-6 * kcs;
  return length(a.r - b.r, a.c - b.c) > 1e-6;
}

// Chooses a node's two shapes: the two best distinct exact pieces (quality <= gate) when there
// are two (a crease between two slope-kappa surfaces), else the best plane and the best cone or
// bowl. `fallback_plane` (or -1) is the plane to keep when no plane is an exact piece.
void select_shapes(const Candidate* cands, int n, double gate, double kcs, int fallback_plane, SourceNode& node,
                   std::array<double, 2>& quality) {
  auto best = [&](auto accept) {
    int at = -1;
    for (int k = 0; k < n; ++k)
      if (cands[k].shape.kind != Shape::Kind::kNone && accept(k) && (at < 0 || cands[k].quality < cands[at].quality))
        at = k;
    return at;
  };
  const int exact = best([&](int k) { return cands[k].quality <= gate; });
  const int other_exact = exact < 0 ? -1 : best([&](int k) {
    return cands[k].quality <= gate && distinct(cands[k].shape, cands[exact].shape, kcs);
  });
  int pick[2] = {exact, other_exact};
  if (other_exact < 0) {
    const bool exact_plane = exact >= 0 && cands[exact].shape.kind == Shape::Kind::kPlane;
    pick[0] = exact_plane || fallback_plane < 0
                  ? best([&](int k) { return cands[k].shape.kind == Shape::Kind::kPlane; })
                  : fallback_plane;
    pick[1] = best([&](int k) { return cands[k].shape.kind != Shape::Kind::kPlane; });
    if (pick[0] >= 0 && pick[1] >= 0 && cands[pick[1]].quality < cands[pick[0]].quality) std::swap(pick[0], pick[1]);
    if (pick[0] < 0) std::swap(pick[0], pick[1]);
  }
  for (int slot = 0; slot < 2; ++slot)
    if (pick[slot] >= 0) {
      node.shapes[slot] = cands[pick[slot]].shape;
      quality[slot] = cands[pick[slot]].quality;
    }
}

// Upper bound of residual(x, q) over the sources q of `kid`, from the kid's own bounds.
double bound_over_child(const Shape& x, const SourceNode& kid, double kcs) {
  const double corners_r[2] = {static_cast<double>(kid.r0), static_cast<double>(kid.r1)};
  const double corners_c[2] = {static_cast<double>(kid.c0), static_cast<double>(kid.c1)};
  // Max over the box corners of a convex function of q.
  auto corner_max = [&](auto f) {
    double best = -kInf;
    for (double r : corners_r)
      for (double c : corners_c) best = std::max(best, f(r, c));
    return best;
  };
  const double x_sign = x.kind == Shape::Kind::kCone ? 1.0 : -1.0;
  double best;
  if (x.kind == Shape::Kind::kPlane) {
    best = kid.max_h + corner_max([&](double r, double c) { return -x.ar * (r - x.r) - x.ac * (c - x.c); });
  } else if (x.kind == Shape::Kind::kCone) {
    best = kid.max_h + corner_max([&](double r, double c) { return kcs * length(r - x.r, c - x.c); });
  } else {
    const double nr = std::max({0.0, kid.r0 - x.r, x.r - kid.r1}), nc = std::max({0.0, kid.c0 - x.c, x.c - kid.c1});
    best = kid.max_h - kcs * length(nr, nc);
  }
  for (const Shape& y : kid.shapes) {
    if (y.kind == Shape::Kind::kNone) continue;
    double b = kInf;
    if (y.kind == Shape::Kind::kPlane) {
      // h(q) <= y.m + a_y.(q - ref_y): minus a plane or plus kcs |q - c| stays convex in q.
      if (x.kind == Shape::Kind::kPlane) {
        b = corner_max([&](double r, double c) {
          return y.m + y.ar * (r - y.r) + y.ac * (c - y.c) - x.ar * (r - x.r) - x.ac * (c - x.c);
        });
      } else if (x.kind == Shape::Kind::kCone) {
        b = corner_max([&](double r, double c) {
          return y.m + y.ar * (r - y.r) + y.ac * (c - y.c) + kcs * length(r - x.r, c - x.c);
        });
      }
    } else {
      const double y_sign = y.kind == Shape::Kind::kCone ? 1.0 : -1.0;
      const double apart = kcs * length(x.r - y.r, x.c - y.c);
      if (x.kind == Shape::Kind::kPlane) {
        // h(q) <= y.m + kcs |q - c_y| (bowl): convex after subtracting a plane.
        if (y_sign < 0)
          b = corner_max([&](double r, double c) {
            return y.m + kcs * length(r - y.r, c - y.c) - x.ar * (r - x.r) - x.ac * (c - x.c);
          });
      } else if (x_sign == y_sign) {
        b = y.m + apart;  // |q - c_x| - |q - c_y| <= |c_x - c_y|
      } else if (x_sign < 0) {
        b = y.m - apart;  // bowl over a cone: -|q - c_x| - |q - c_y| <= -|c_x - c_y|
      } else {
        b = corner_max(
            [&](double r, double c) { return y.m + kcs * (length(r - y.r, c - y.c) + length(r - x.r, c - x.c)); });
      }
    }
    best = std::min(best, b);
  }
  return best;
}

}  // namespace

struct SourceTree::Builder {
  const Problem& pb;
  SourceTree& tree;
  double gate;  // quality up to which a shape counts as an exact piece [m]
  std::vector<Moments> moments, next_moments;
  std::vector<std::array<double, 2>> quality, next_quality;

  void build_leaf(int bi, int bj, SourceNode& node, Moments& mom, std::array<double, 2>& q) {
    const std::uint64_t mask = tree.leaf_mask(bi, bj);
    if (!mask) return;
    Point pts[kBlock * kBlock];
    int all[kBlock * kBlock], quadrant[4][kBlock * kBlock], quadrant_n[4] = {0, 0, 0, 0};
    int n = 0;
    for (std::uint64_t bits = mask; bits; bits &= bits - 1) {
      const int b = __builtin_ctzll(bits), lr = b / kBlock, lc = b % kBlock;
      const int r = bi * kBlock + lr, c = bj * kBlock + lc;
      pts[n] = {static_cast<double>(r), static_cast<double>(c), pb.h[static_cast<std::int64_t>(r) * pb.cols + c]};
      const int qi = (lr >= kBlock / 2 ? 2 : 0) + (lc >= kBlock / 2 ? 1 : 0);
      quadrant[qi][quadrant_n[qi]++] = n;
      all[n] = n;
      node.r0 = n == 0 ? r : std::min(node.r0, r);
      node.r1 = n == 0 ? r : std::max(node.r1, r);
      node.c0 = n == 0 ? c : std::min(node.c0, c);
      node.c1 = n == 0 ? c : std::max(node.c1, c);
      node.max_h = std::max(node.max_h, pts[n].h);
      ++n;
    }
    mom = Moments::of(pts, all, n);

    Candidate cands[3 + 8];
    int count = 0;
    // m over every point of the leaf; quality = m - min residual over the points it was fit to.
    auto add = [&](Shape s, const int* idx, int idx_n, bool only_exact) {
      if (s.kind == Shape::Kind::kNone) return;
      double own_min = kInf, own_max = -kInf;
      for (int k = 0; k < idx_n; ++k) {
        const double v = residual(s, pb.kcs, pts[idx[k]].r, pts[idx[k]].c, pts[idx[k]].h);
        own_min = std::min(own_min, v);
        own_max = std::max(own_max, v);
      }
      if (only_exact && own_max - own_min > gate) return;
      s.m = -kInf;
      for (int k = 0; k < n; ++k) s.m = std::max(s.m, residual(s, pb.kcs, pts[k].r, pts[k].c, pts[k].h));
      cands[count++] = {s, s.m - own_min};
    };
    double raw_slope = 0;
    add(mom.plane(pb.kcs, &raw_slope), all, n, false);
    double lowest = kInf;
    for (int k = 0; k < n; ++k) lowest = std::min(lowest, pts[k].h);
    // A slope-kappa cone or bowl rises by at least 4.25 cells' drop across a whole leaf (from its apex to the farthest
    // corner when the apex is inside, the leaf's width of 7 cells or more when it is outside), and away from its apex
    // the leaf's least-squares slope is near kappa: a leaf that is flatter and lower than that (most of a rough
    // terrain's) gets no fit. The fit only tightens bounds; a partial leaf that loses it stays exact.
    const bool may_be_apex = raw_slope >= 0.5 * pb.kcs || node.max_h - lowest >= 4.0 * pb.kcs;
    // A cone or bowl only where the plane is not already exact and the points may lie on one.
    if (cands[0].quality > gate && may_be_apex) add(fit_apex(pts, all, n, pb.kcs, kFitSpread * pb.kcs), all, n, false);
    int top = 0;
    for (int k = 1; k < n; ++k)
      if (pts[k].h > pts[top].h) top = k;
    Shape peak;
    peak.kind = Shape::Kind::kCone;
    peak.r = pts[top].r;
    peak.c = pts[top].c;
    add(peak, &top, 1, false);
    double best = kInf;
    for (int k = 0; k < count; ++k) best = std::min(best, cands[k].quality);
    if (best > gate) {
      // Maybe a crease between two exact pieces: fit each quadrant on its own. A slope-kappa
      // cone or bowl piece away from its apex has a least-squares slope near kappa.
      for (int qi = 0; qi < 4; ++qi) {
        if (quadrant_n[qi] < 5) continue;
        double raw_slope = 0;
        add(Moments::of(pts, quadrant[qi], quadrant_n[qi]).plane(pb.kcs, &raw_slope), quadrant[qi], quadrant_n[qi],
            true);
        if (raw_slope >= 0.5 * pb.kcs && raw_slope <= 1.5 * pb.kcs)
          add(fit_apex(pts, quadrant[qi], quadrant_n[qi], pb.kcs, kFitSpread * pb.kcs), quadrant[qi], quadrant_n[qi],
              true);
      }
    }
    select_shapes(cands, count, gate, pb.kcs, -1, node, q);
  }

  // Exact m of a shape over every source below node (level, i, j).
  double exact_m(const Shape& s, int level, int i, int j) const {
    const int span = 1 << level;
    const int i_end = std::min(tree.heights_[0], (i + 1) * span), j_end = std::min(tree.widths_[0], (j + 1) * span);
    double m = -kInf;
    for (int li = i * span; li < i_end; ++li)
      for (int lj = j * span; lj < j_end; ++lj)
        for (std::uint64_t bits = tree.leaf_mask(li, lj); bits; bits &= bits - 1) {
          const int b = __builtin_ctzll(bits);
          const int r = li * kBlock + b / kBlock, c = lj * kBlock + b % kBlock;
          m = std::max(m, residual(s, pb.kcs, r, c, pb.h[static_cast<std::int64_t>(r) * pb.cols + c]));
        }
    return m;
  }

  void build_inner(int level, int i, int j, SourceNode& node, Moments& mom, std::array<double, 2>& q) {
    const std::vector<SourceNode>& below = tree.levels_[level - 1];
    const int cw = tree.widths_[level - 1], ch = tree.heights_[level - 1];
    const SourceNode* kids[4];
    const std::array<double, 2>* kid_quality[4];
    int n = 0;
    auto grow = [&node](const SourceNode& kid) {
      if (node.empty()) {
        node.r0 = kid.r0, node.r1 = kid.r1, node.c0 = kid.c0, node.c1 = kid.c1;
      } else {
        node.r0 = std::min(node.r0, kid.r0), node.r1 = std::max(node.r1, kid.r1);
        node.c0 = std::min(node.c0, kid.c0), node.c1 = std::max(node.c1, kid.c1);
      }
      node.max_h = std::max(node.max_h, kid.max_h);
    };
    for (int di = 0; di < 2; ++di)
      for (int dj = 0; dj < 2; ++dj) {
        const int ci = 2 * i + di, cj = 2 * j + dj;
        if (ci >= ch || cj >= cw) continue;
        const std::size_t at = static_cast<std::size_t>(ci) * cw + cj;
        if (below[at].empty()) continue;
        kids[n] = &below[at];
        kid_quality[n] = &quality[at];
        ++n;
        mom.merge(moments[at]);
        grow(below[at]);
      }
    if (n == 0) return;
    Candidate cands[9];
    int count = 0;
    auto merged_m = [&](const Shape& s) {
      double m = -kInf;
      for (int k = 0; k < n; ++k) m = std::max(m, bound_over_child(s, *kids[k], pb.kcs));
      return m;
    };
    for (int k = 0; k < n; ++k)
      for (int slot = 0; slot < 2; ++slot) {
        Shape s = kids[k]->shapes[slot];
        if (s.kind == Shape::Kind::kNone) continue;
        const double own = s.m, own_quality = (*kid_quality[k])[slot];
        s.m = merged_m(s);
        if (own_quality <= gate && s.m - own > pb.tol && level <= kExactLevels) s.m = exact_m(s, level, i, j);
        cands[count++] = {s, own_quality + (s.m - own)};
      }
    Shape plane = mom.plane(pb.kcs);
    plane.m = merged_m(plane);
    cands[count++] = {plane, plane.m - mom.mh};  // a rough quality: the lift above the mean
    select_shapes(cands, count, gate, pb.kcs, count - 1, node, q);
  }
};

SourceTree::SourceTree(const Problem& pb, std::vector<std::uint64_t> masks) : masks_(std::move(masks)) {
  const int leaf_rows = (pb.rows + kBlock - 1) / kBlock, leaf_cols = (pb.cols + kBlock - 1) / kBlock;
  Builder b{pb, *this, pb.tol, {}, {}, {}, {}};
  widths_.push_back(leaf_cols);
  heights_.push_back(leaf_rows);
  levels_.emplace_back(static_cast<std::size_t>(leaf_rows) * leaf_cols);
  b.moments.resize(levels_[0].size());
  b.quality.assign(levels_[0].size(), {kInf, kInf});
  for (int i = 0; i < leaf_rows; ++i)
    for (int j = 0; j < leaf_cols; ++j) {
      const std::size_t at = static_cast<std::size_t>(i) * leaf_cols + j;
      b.build_leaf(i, j, levels_[0][at], b.moments[at], b.quality[at]);
    }
  while (widths_.back() > 1 || heights_.back() > 1) {
    const int w = (widths_.back() + 1) / 2, h = (heights_.back() + 1) / 2;
    const int level = static_cast<int>(levels_.size());
    levels_.emplace_back(static_cast<std::size_t>(w) * h);
    widths_.push_back(w);
    heights_.push_back(h);
    b.next_moments.assign(levels_.back().size(), Moments{});
    b.next_quality.assign(levels_.back().size(), {kInf, kInf});
    for (int i = 0; i < h; ++i)
      for (int j = 0; j < w; ++j) {
        const std::size_t at = static_cast<std::size_t>(i) * w + j;
        b.build_inner(level, i, j, levels_[level][at], b.next_moments[at], b.next_quality[at]);
      }
    b.moments.swap(b.next_moments);
    b.quality.swap(b.next_quality);
  }
}

}  // namespace marsala::detail
