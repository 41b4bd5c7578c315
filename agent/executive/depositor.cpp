#include "marsala/agent/executive/depositor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/registry.hpp"

namespace marsala::agent::executive {
namespace {

/// One deposit and the cells it is predicted to raise (local indices).
struct Placed {
  Deposit deposit;
  std::vector<DepositionCandidate> rises;
};

/// The plan of the longest prefix of `placed` that keeps the way back (the empty one always does).
DepositionPlan keep_way_back(const DepositionManager& manager, const deliberative::LocalMap& map, Position robot,
                             const Neighbourhood& neighbours, const std::vector<Placed>& placed) {
  const auto rises_of = [&](std::size_t count) {
    std::vector<DepositionCandidate> rises;
    for (std::size_t i = 0; i < count; ++i) rises.insert(rises.end(), placed[i].rises.begin(), placed[i].rises.end());
    return rises;
  };
  DepositionPlan plan;
  plan.candidates = static_cast<int>(placed.size());
  std::size_t good = placed.size();
  DepositionManager::WayBack way = manager.way_back(map, robot, neighbours);
  if (!manager.keeps_way_back(way, rises_of(good))) {
    std::size_t ok = 0, bad = placed.size();
    while (bad - ok > 1) {
      const std::size_t mid = ok + (bad - ok) / 2;
      (manager.keeps_way_back(way, rises_of(mid)) ? ok : bad) = mid;
    }
    good = ok;
  }
  plan.dropped_for_way_back = static_cast<int>(placed.size() - good);
  for (std::size_t i = 0; i < good; ++i) {
    plan.deposits.push_back(placed[i].deposit);
    plan.volume_m3 += placed[i].deposit.volume_m3;
  }
  return plan;
}

double budget_m3(const DepositionManager& manager, double material_m3) {
  return std::min(manager.params().max_deposit_m3, std::max(material_m3, 0.0));
}

class LayerDepositor final : public Depositor {
 public:
  std::string name() const override { return "layer"; }
  DepositionPlan plan(const DepositionManager& manager, const deliberative::LocalMap& map,
                      const std::vector<CellIndex>& path, Position robot, double material_m3,
                      const Neighbourhood& neighbours) const override {
    return manager.plan(map, path, robot, material_m3, neighbours);
  }
};

class CubeDepositor final : public Depositor {
 public:
  explicit CubeDepositor(double side_m) : side_m_(side_m) {}
  std::string name() const override { return "cube"; }

  DepositionPlan plan(const DepositionManager& manager, const deliberative::LocalMap& map,
                      const std::vector<CellIndex>& path, Position robot, double material_m3,
                      const Neighbourhood& neighbours) const override {
    const DepositionParams& p = manager.params();
    // What each cell still wants [m]; negative: it may not be raised.
    std::vector<double> remaining(static_cast<std::size_t>(map.rows()) * map.cols(), -1.0);
    const auto index = [&](CellIndex c) { return static_cast<std::size_t>(c.row) * map.cols() + c.col; };
    const std::vector<WantedCell> wanted = manager.wanted(map, path, robot, neighbours);
    for (const WantedCell& w : wanted) remaining[index(w.cell)] = w.gap_m;
    const double cube_m3 = side_m_ * side_m_ * side_m_;
    double budget = budget_m3(manager, material_m3);
    std::vector<Placed> placed;
    // Columns centred on the wanted cells in path order (contour crafting along the path), each as tall as every
    // cell of its footprint still wants: never above the MARS height.
    for (const WantedCell& w : wanted) {
      int cubes = static_cast<int>(std::floor(budget / cube_m3 + 1e-9));
      if (cubes < 1) break;
      const Position centre = map.world.cell_center(map.to_global(w.cell));
      if (!(distance(centre, robot) <= p.reach_m)) continue;
      const DepositShape one = cube_column_shape(map.world, centre, side_m_, 1);
      if (!one.on_grid || one.rises.empty()) continue;
      for (const CellRise& r : one.rises) {
        const CellIndex local = map.to_local(r.cell);
        const double want = map.contains(local) ? remaining[index(local)] : -1.0;
        cubes = want < 0.0 ? 0 : std::min(cubes, static_cast<int>(std::floor(want / r.rise_m + 1e-9)));
        cubes = std::min(cubes, static_cast<int>(std::floor(p.max_height_m / r.rise_m + 1e-9)));
        if (cubes < 1) break;
      }
      if (cubes < 1) continue;
      Placed column{{centre.x, centre.y, cubes * cube_m3}, {}};
      for (const CellRise& r : cube_column_shape(map.world, centre, side_m_, cubes).rises) {
        const CellIndex local = map.to_local(r.cell);
        remaining[index(local)] = std::max(0.0, remaining[index(local)] - r.rise_m);
        column.rises.push_back({local, 0, r.rise_m});
      }
      budget -= cubes * cube_m3;
      placed.push_back(std::move(column));
    }
    return keep_way_back(manager, map, robot, neighbours, placed);
  }

 private:
  double side_m_;
};

/// The largest pile [m^3] dumped at `dump` [m] on `heights` whose every cell stays within what it may still take
/// (`remaining` [m] per cell of the window, row-major; negative: it may not rise at all; at most `max_rise_m`), and
/// that reaches no cell of the window's outermost ring (beyond it the map is not known) and stays `margin_m` below
/// every cell it may not raise. A pile at apex z raises the cells whose base h(p) + slope |p - dump| lies below z, each
/// to z - slope |p - dump|: the pile fits when z stays at or below every cell's base plus what the cell may take, so
/// the largest apex is the least of those, and its volume follows (as cone_pile_shape() fills, up to rounding).
double largest_pile_m3(const Heightmap& heights, const std::vector<double>& remaining, Position dump, double slope,
                       double max_rise_m, double margin_m) {
  const int rows = heights.rows(), cols = heights.cols();
  std::vector<double> base(remaining.size());
  double apex = std::numeric_limits<double>::infinity();
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * cols + c;
      const Position centre = heights.cell_center({r, c});
      base[i] = heights(r, c) + slope * distance(centre, dump);
      const bool edge = r == 0 || c == 0 || r == rows - 1 || c == cols - 1;
      const double may = edge ? 0.0 : std::min(remaining[i], max_rise_m);
      apex = std::min(apex, base[i] + (may < 0.0 ? -margin_m : may));
    }
  double fill_m = 0.0;
  for (const double b : base) fill_m += std::max(0.0, apex - b);
  const double cs = heights.cell_size_m();
  return fill_m * cs * cs;
}

class ConeDepositor final : public Depositor {
 public:
  explicit ConeDepositor(double repose_deg) : repose_deg_(repose_deg) {}
  std::string name() const override { return "cone"; }

  DepositionPlan plan(const DepositionManager& manager, const deliberative::LocalMap& map,
                      const std::vector<CellIndex>& path, Position robot, double material_m3,
                      const Neighbourhood& neighbours) const override {
    const DepositionParams& p = manager.params();
    const auto index = [&](CellIndex c) { return static_cast<std::size_t>(c.row) * map.cols() + c.col; };
    // What each cell may still take [m]: its MARS gap where it may be raised at all, negative where it may not.
    std::vector<double> remaining(static_cast<std::size_t>(map.rows()) * map.cols(), -1.0);
    const double clear_m = manager.clearance_m(map, robot);
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (map.blind(r, c) == 0 && manager.may_raise(map, {r, c}, robot, neighbours, clear_m))
          remaining[index({r, c})] = std::max(0.0, deliberative::rise_wanted_m(map, {r, c}, 0.0));
    const std::vector<WantedCell> wanted = manager.wanted(map, path, robot, neighbours, clear_m);
    std::vector<std::uint8_t> in_band(remaining.size(), 0);  // the cells the path's footprint wants
    for (const WantedCell& w : wanted) in_band[index(w.cell)] = 1;
    Heightmap heights = map.heights;  // the piles chosen so far land on it
    const double lowest = heights.min_height();  // the piles only raise cells: still the window's lowest after them
    double budget = budget_m3(manager, material_m3);
    std::vector<Placed> placed;
    for (int pile = 0; pile < kMaxConesPerStep && budget > kMinVolumeM3; ++pile) {
      Choice best;
      int points = 0;
      for (const WantedCell& w : wanted) {
        if (points >= kConeDumpPoints) break;
        const Position dump = map.center(w.cell);
        if (!(remaining[index(w.cell)] > 0.0) || !(distance(dump, robot) <= p.reach_m)) continue;
        ++points;
        consider(heights, remaining, in_band, dump, budget, p.max_height_m, {p.pile_margin_m, lowest}, best);
      }
      if (!(best.band_m3 > 0.0)) break;
      Placed pile_placed{{best.dump.x, best.dump.y, best.volume_m3}, {}};
      for (const CellRise& r : best.shape.rises) {
        heights(r.cell) += r.rise_m;
        remaining[index(r.cell)] = std::max(0.0, remaining[index(r.cell)] - r.rise_m);
        pile_placed.rises.push_back({r.cell, 0, r.rise_m});
      }
      budget -= best.volume_m3;
      placed.push_back(std::move(pile_placed));
    }
    return keep_way_back(manager, map, robot, neighbours, placed);
  }

 private:
  /// How far a pile stays below the cells it may not raise (clear_by()), with the window's lowest height [m].
  struct Clearance {
    double margin_m = 0.0;
    double lowest_m = 0.0;
  };

  /// The best pile found so far.
  struct Choice {
    double band_m3 = 0.0;  // its volume on the path's footprint [m^3]
    Position dump;
    double volume_m3 = 0.0;
    DepositShape shape;
  };

  /// The piles dumped at `dump` that fit against `best`: the largest that fits (its apex at the MARS height where
  /// the cells' caps allow), the budget and its halvings, and what fills the dump cell alone; the one with most
  /// volume on the path's footprint wins.
  void consider(const Heightmap& heights, const std::vector<double>& remaining, const std::vector<std::uint8_t>& in_band,
                Position dump, double budget, double max_rise_m, Clearance clearance, Choice& best) const {
    const double area = heights.cell_size_m() * heights.cell_size_m();
    const auto index = [&](CellIndex c) { return static_cast<std::size_t>(c.row) * heights.cols() + c.col; };
    std::vector<double> volumes{
        std::min(budget, largest_pile_m3(heights, remaining, dump, slope_, max_rise_m, clearance.margin_m) *
                             (1.0 - kShrinkFraction))};
    for (double v = budget; volumes.size() <= kVolumeHalvings; v *= 0.5) volumes.push_back(v);
    const double here = remaining[index(*heights.geometry().cell_at(dump))] * area;
    if (here < budget) volumes.push_back(here);  // fills the dump cell alone when the pile stays in it
    for (const double v : volumes) {
      if (!(v > kMinVolumeM3)) continue;
      DepositShape shape = cone_pile_shape(heights, dump, v, repose_deg_);
      if (!shape.on_grid) continue;  // the pile reaches the window's edge: beyond it the map is not known
      double band = 0.0;
      bool ok = true;
      for (const CellRise& r : shape.rises) {
        const double may = remaining[index(r.cell)];
        if (may < 0.0 || r.rise_m > may + kConeRoundingM || r.rise_m > max_rise_m) {
          ok = false;
          break;
        }
        if (in_band[index(r.cell)]) band += std::min(r.rise_m, may) * area;
      }
      if (!ok || !(band > best.band_m3 + 1e-12)) continue;
      // The world computes the pile on its own copy of the terrain, in its own frame: a cell at the pile's edge
      // may rise there by rounding. A slightly bigger pile covers every cell this one could (the cells rising
      // grow with the volume), so it must not reach a cell this robot may not raise either.
      const DepositShape guard = cone_pile_shape(heights, dump, v * (1.0 + kGuardFraction), repose_deg_);
      bool guarded = guard.on_grid;
      for (const CellRise& r : guard.rises)
        if (remaining[index(r.cell)] < 0.0) guarded = false;
      if (!guarded || !clear_by(heights, remaining, dump, shape, clearance)) continue;
      best = {band, dump, v, std::move(shape)};
    }
  }

  /// True when the pile `shape` dumped at `dump` stays the clearance's margin below every cell of the window it may
  /// not raise (remaining < 0): on a scanned map those cells read within noise, and the world settles the pile on the
  /// truth.
  bool clear_by(const Heightmap& heights, const std::vector<double>& remaining, Position dump, const DepositShape& shape,
                Clearance clearance) const {
    const double margin_m = clearance.margin_m;
    if (!(margin_m > 0.0) || shape.rises.empty()) return true;
    const double cs = heights.cell_size_m();
    double apex = -std::numeric_limits<double>::infinity();
    for (const CellRise& r : shape.rises)
      apex = std::max(apex, heights(r.cell) + r.rise_m + slope_ * distance(heights.cell_center(r.cell), dump));
    // Cells farther than this from the dump point lie below the pile only if they are lower than the window's lowest.
    const double reach_m = (apex + margin_m - clearance.lowest_m) / slope_;
    const int span = static_cast<int>(std::ceil(reach_m / cs)) + 1;
    const CellIndex at = *heights.geometry().cell_at(dump);
    for (int r = std::max(0, at.row - span); r <= std::min(heights.rows() - 1, at.row + span); ++r)
      for (int c = std::max(0, at.col - span); c <= std::min(heights.cols() - 1, at.col + span); ++c)
        if (remaining[static_cast<std::size_t>(r) * heights.cols() + c] < 0.0 &&
            apex - slope_ * distance(heights.cell_center({r, c}), dump) > heights(r, c) - margin_m)
          return false;
    return true;
  }

  static constexpr double kMinVolumeM3 = 1e-7;  // smaller piles are not worth a deposit [m^3]
  static constexpr std::size_t kVolumeHalvings = 6;  // volumes tried besides: the budget, half of it, ... 1/32 of it
  static constexpr double kGuardFraction = 1e-6;  // the guard pile's extra volume, relative
  static constexpr double kShrinkFraction = 4e-6;  // the largest pile, a little smaller: its guard fits too
  double repose_deg_;
  double slope_ = std::tan(repose_deg_ * 3.14159265358979323846 / 180.0);
};

using DepositorRegistry = Registry<Depositor, const RobotType&>;

void register_builtins(DepositorRegistry& r) {
  r.add("layer", [](const RobotType&) { return std::make_unique<LayerDepositor>(); });
  r.add("cube", [](const RobotType& t) { return std::make_unique<CubeDepositor>(depositor_cube_size_m(t)); });
  r.add("cone", [](const RobotType& t) { return std::make_unique<ConeDepositor>(t.depositor.repose_deg); });
}

const DepositorRegistry& registry() {
  static const DepositorRegistry r = [] {
    DepositorRegistry out("depositor");
    register_builtins(out);
    return out;
  }();
  return r;
}

}  // namespace

std::unique_ptr<Depositor> make_depositor(const RobotType& type) {
  return registry().make(to_string(type.depositor.kind), type);
}

}  // namespace marsala::agent::executive
