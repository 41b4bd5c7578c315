#include "marsala/core/goal_vector_map.hpp"

#include <algorithm>
#include <cmath>

#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala {
namespace {

constexpr EnumName<Heading> kHeadingNames[] = {
    {Heading::kEast, "east"}, {Heading::kWest, "west"}, {Heading::kNorth, "north"}, {Heading::kSouth, "south"}};

// Lengths computed from user metres (x1 - x0, k * L) carry rounding; comparisons against one cell or the grid's
// extent forgive this much [m].
constexpr double kTolM = 1e-9;

[[noreturn]] void fail(const std::string& problem) {
  throw InvalidArgument(fmt::format("goal vector map: {}", problem));
}

void check_finite(const char* field, double v) {
  if (!std::isfinite(v)) fail(fmt::format("{} is {}, not a finite number", field, v));
}

bool along_x(Heading h) { return h == Heading::kEast || h == Heading::kWest; }
bool forward(Heading h) { return h == Heading::kEast || h == Heading::kNorth; }

// Pieces of n units of `size` covering `extent`, the last one possibly shorter: ceil(extent / size), at least 1;
// a quotient a rounding error above an integer does not open an extra, empty piece.
int pieces(double extent, double size) { return std::max(1, static_cast<int>(std::ceil(extent / size - kTolM))); }

}  // namespace

std::string to_string(Heading heading) { return enum_to_string(kHeadingNames, heading); }

Heading heading_from_string(const std::string& name) { return enum_from_string(kHeadingNames, name, "heading"); }

GoalVectorMap::GoalVectorMap(const GoalVectorMapSpec& spec, const GridGeometry& grid) : spec_(spec) {
  check_finite("x0_m", spec.area.x0);
  check_finite("y0_m", spec.area.y0);
  check_finite("x1_m", spec.area.x1);
  check_finite("y1_m", spec.area.y1);
  check_finite("strip_width_m", spec.strip_width_m);
  check_finite("arrow_length_m", spec.arrow_length_m);
  const double cs = grid.cell_size_m;
  if (grid.rows <= 0 || grid.cols <= 0 || !std::isfinite(cs) || !(cs > 0.0) || !std::isfinite(grid.xll_m) ||
      !std::isfinite(grid.yll_m))
    fail(fmt::format("the grid {} x {} with cell size {} m is not a valid grid", grid.rows, grid.cols, cs));
  if (!(spec.area.x0 < spec.area.x1) || !(spec.area.y0 < spec.area.y1))
    fail(fmt::format("the rectangle {} is empty (needs x0_m < x1_m and y0_m < y1_m)", spec.area));
  const double gx1 = grid.xll_m + grid.cols * cs;
  const double gy1 = grid.yll_m + grid.rows * cs;
  if (spec.area.x0 < grid.xll_m - kTolM || spec.area.x1 > gx1 + kTolM || spec.area.y0 < grid.yll_m - kTolM ||
      spec.area.y1 > gy1 + kTolM)
    fail(fmt::format("the rectangle {} is not inside the grid {}", spec.area, Rect{grid.xll_m, grid.yll_m, gx1, gy1}));
  if (!(spec.strip_width_m > 0.0)) fail(fmt::format("strip_width_m is {}, must be > 0", spec.strip_width_m));
  if (!(spec.arrow_length_m > 0.0)) fail(fmt::format("arrow_length_m is {}, must be > 0", spec.arrow_length_m));
  if (spec.strip_width_m < cs - kTolM)
    fail(fmt::format("strip_width_m {} m is narrower than one cell ({} m)", spec.strip_width_m, cs));
  if (spec.arrow_length_m < cs - kTolM)
    fail(fmt::format("arrow_length_m {} m is shorter than one cell ({} m)", spec.arrow_length_m, cs));

  const Heading heading = spec.heading;
  const bool ax = along_x(heading);
  const bool fwd = forward(heading);
  const double across_lo = ax ? spec.area.y0 : spec.area.x0;
  const double across_hi = ax ? spec.area.y1 : spec.area.x1;
  const double along_lo = ax ? spec.area.x0 : spec.area.y0;
  const double along_hi = ax ? spec.area.x1 : spec.area.y1;
  const double w = spec.strip_width_m;
  const double len = spec.arrow_length_m;

  // Snaps a point to the centre of its cell; points on the far (high-coordinate) edges would fall into the cell
  // beyond, so they move half a cell inwards first. Clamping only absorbs the tolerance of the inside check.
  const auto snap = [&](double x, double y) {
    if (x >= spec.area.x1) x = spec.area.x1 - 0.5 * cs;
    if (y >= spec.area.y1) y = spec.area.y1 - 0.5 * cs;
    const int col = std::clamp(static_cast<int>(std::floor((x - grid.xll_m) / cs)), 0, grid.cols - 1);
    const int row_from_south = std::clamp(static_cast<int>(std::floor((y - grid.yll_m) / cs)), 0, grid.rows - 1);
    return grid.cell_center({grid.rows - 1 - row_from_south, col});
  };
  // Coordinate along the heading of a snapped point, and across it.
  const auto along_of = [&](Position p) { return ax ? p.x : p.y; };
  const auto across_of = [&](Position p) { return ax ? p.y : p.x; };
  const auto point = [&](double along, double across) { return ax ? snap(along, across) : snap(across, along); };

  // Strip centre lines across the heading, strip 0 at the low side; the last band may be narrower, but not
  // narrower than a cell (its centre line would leave the rectangle or share a cell with its neighbour's).
  strips_ = pieces(across_hi - across_lo, w);
  const double last_band_lo = across_lo + (strips_ - 1) * w;
  if (across_hi - last_band_lo < cs - kTolM)
    fail(fmt::format(
        "strip {} of {} is only {} m wide, narrower than one cell ({} m): the site is {} m across heading {} with "
        "strip_width_m {} m",
        strips_ - 1, strips_, across_hi - last_band_lo, cs, across_hi - across_lo, to_string(heading), w));
  std::vector<double> lines(static_cast<std::size_t>(strips_));
  for (int i = 0; i < strips_; ++i) {
    const double lo = across_lo + i * w;
    const double hi = i + 1 < strips_ ? across_lo + (i + 1) * w : across_hi;
    lines[static_cast<std::size_t>(i)] = across_of(point(fwd ? along_lo : along_hi, 0.5 * (lo + hi)));
  }

  // Cut points along the heading: the upwind edge, every arrow length, the downwind edge (set exactly, not as
  // lo + extent, so the far-edge rule sees it).
  const double extent = along_hi - along_lo;
  const int n = pieces(extent, len);
  const auto travelled = [&](int k) { return k == n ? extent : k * len; };  // from the upwind edge [m]
  const auto cut = [&](int k) {
    if (k == 0) return fwd ? along_lo : along_hi;
    if (k == n) return fwd ? along_hi : along_lo;
    return fwd ? along_lo + k * len : along_hi - k * len;
  };
  std::vector<double> snapped(static_cast<std::size_t>(n) + 1);
  for (int k = 0; k <= n; ++k) snapped[static_cast<std::size_t>(k)] = along_of(point(cut(k), lines[0]));
  // Signed advance along the heading between two snapped cut points [m].
  const auto advance = [&](int a, int b) {
    const double d = snapped[static_cast<std::size_t>(b)] - snapped[static_cast<std::size_t>(a)];
    return fwd ? d : -d;
  };
  // Snapping moves a point by up to half a cell, so an arrow that is one cell long on paper can shrink to nothing
  // (or point backwards at the far edge). Cut points that would make an arrow shorter than one cell are dropped,
  // which merges that arrow into its neighbour; the remainder at the downwind edge is merged into the previous
  // arrow when it is shorter than one cell on paper or after snapping.
  std::vector<int> kept{0};
  for (int k = 1; k < n; ++k)
    if (advance(kept.back(), k) >= cs - kTolM) kept.push_back(k);
  while (kept.size() > 1 &&
         (travelled(n) - travelled(kept.back()) < cs - kTolM || advance(kept.back(), n) < cs - kTolM))
    kept.pop_back();
  if (advance(kept.back(), n) < cs - kTolM)
    fail(fmt::format(
        "the site is only {} m long along heading {}: its upwind and downwind cells are less than one cell ({} m) "
        "apart",
        extent, to_string(heading), cs));
  kept.push_back(n);

  arrows_.reserve(static_cast<std::size_t>(strips_) * (kept.size() - 1));
  for (int i = 0; i < strips_; ++i) {
    const double across = lines[static_cast<std::size_t>(i)];
    for (std::size_t j = 0; j + 1 < kept.size(); ++j) {
      GoalArrow a;
      a.tail = point(cut(kept[j]), across);
      a.head = point(cut(kept[j + 1]), across);
      a.strip = i;
      a.index = static_cast<int>(j);
      arrows_.push_back(a);
    }
  }
}

std::optional<std::size_t> GoalVectorMap::nearest_free_tail(Position p, const std::vector<bool>& excluded) const {
  if (!std::isfinite(p.x) || !std::isfinite(p.y))
    fail(fmt::format("nearest_free_tail from {}: not a finite position", p));
  std::optional<std::size_t> best;
  double best_d2 = 0.0;
  for (std::size_t i = 0; i < arrows_.size(); ++i) {
    if (i < excluded.size() && excluded[i]) continue;
    const double dx = arrows_[i].tail.x - p.x;
    const double dy = arrows_[i].tail.y - p.y;
    const double d2 = dx * dx + dy * dy;
    if (!best || d2 < best_d2) {
      best = i;
      best_d2 = d2;
    }
  }
  return best;
}

std::optional<std::size_t> GoalVectorMap::arrow_at(Position p) const {
  const Rect& a = spec_.area;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || p.x < a.x0 - kTolM || p.x > a.x1 + kTolM || p.y < a.y0 - kTolM ||
      p.y > a.y1 + kTolM)
    return std::nullopt;
  const bool ax = along_x(spec_.heading);
  const double across = ax ? p.y - a.y0 : p.x - a.x0;
  const int strip =
      std::clamp(static_cast<int>(std::ceil(across / spec_.strip_width_m - kTolM)) - 1, 0, strips_ - 1);
  const std::size_t per_strip = arrows_.size() / static_cast<std::size_t>(strips_);
  const std::size_t first = static_cast<std::size_t>(strip) * per_strip;
  // Coordinates along the heading grow downwind.
  const double sign = forward(spec_.heading) ? 1.0 : -1.0;
  const double along = sign * (ax ? p.x : p.y);
  for (std::size_t i = first; i + 1 < first + per_strip; ++i) {
    const Position head = arrows_[i].head;
    if (along <= sign * (ax ? head.x : head.y) + kTolM) return i;
  }
  return first + per_strip - 1;
}

std::optional<std::size_t> GoalVectorMap::next(std::size_t i) const {
  if (i >= arrows_.size()) fail(fmt::format("arrow {} is out of range (the map has {} arrows)", i, arrows_.size()));
  if (i + 1 < arrows_.size() && arrows_[i + 1].strip == arrows_[i].strip) return i + 1;
  return std::nullopt;
}

}  // namespace marsala
