#include "marsala/agent/executive/depositor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/registry.hpp"

namespace marsala::agent::executive {
namespace {

double distance(Position a, Position b) { return std::hypot(a.x - b.x, a.y - b.y); }

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
  if (!manager.keeps_way_back(map, robot, rises_of(good), neighbours)) {
    std::size_t ok = 0, bad = placed.size();
    while (bad - ok > 1) {
      const std::size_t mid = ok + (bad - ok) / 2;
      (manager.keeps_way_back(map, robot, rises_of(mid), neighbours) ? ok : bad) = mid;
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

class ConeDepositor final : public Depositor {
 public:
  explicit ConeDepositor(double repose_deg) : repose_deg_(repose_deg) {}
  std::string name() const override { return "cone"; }

  DepositionPlan plan(const DepositionManager& manager, const deliberative::LocalMap& map,
                      const std::vector<CellIndex>& path, Position robot, double material_m3,
                      const Neighbourhood& neighbours) const override {
    const DepositionParams& p = manager.params();
    const double cs = map.geometry().cell_size_m, area = cs * cs;
    const double overshoot_m = kConeOvershootFraction * p.navigability.eps_m;
    const auto index = [&](CellIndex c) { return static_cast<std::size_t>(c.row) * map.cols() + c.col; };
    // What each cell may still take [m]: its MARS gap where it may be raised at all, negative where it may not.
    std::vector<double> remaining(static_cast<std::size_t>(map.rows()) * map.cols(), -1.0);
    for (int r = 0; r < map.rows(); ++r)
      for (int c = 0; c < map.cols(); ++c)
        if (map.blind(r, c) == 0 && manager.may_raise(map, {r, c}, robot, neighbours))
          remaining[index({r, c})] = std::max(0.0, map.gap(r, c));
    const std::vector<WantedCell> wanted = manager.wanted(map, path, robot, neighbours);
    std::vector<std::uint8_t> in_band(remaining.size(), 0);  // the cells the path's footprint wants
    for (const WantedCell& w : wanted) in_band[index(w.cell)] = 1;
    Heightmap heights = map.heights;  // the piles chosen so far land on it
    double budget = budget_m3(manager, material_m3);
    std::vector<Placed> placed;
    for (int pile = 0; pile < kMaxConesPerStep && budget > kMinVolumeM3; ++pile) {
      struct Best {
        double fill_m3 = 0.0;
        double band_m3 = 0.0;  // the part of fill_m3 on the path's footprint
        Position dump;
        double volume_m3 = 0.0;
        DepositShape shape;
      } best;
      int points = 0;
      for (const WantedCell& w : wanted) {
        if (points >= kConeDumpPoints) break;
        const double here = remaining[index(w.cell)];
        const Position dump = map.center(w.cell);
        if (!(here > 0.0) || !(distance(dump, robot) <= p.reach_m)) continue;
        ++points;
        std::vector<double> volumes;
        for (double v = budget; volumes.size() < kVolumeHalvings; v *= 0.5) volumes.push_back(v);
        if (here * area < budget) volumes.push_back(here * area);  // fills this cell alone when the pile stays in it
        for (const double v : volumes) {
          if (!(v > kMinVolumeM3)) continue;
          DepositShape shape = cone_pile_shape(heights, dump, v, repose_deg_);
          if (!shape.on_grid) continue;  // the pile reaches the window's edge: beyond it the map is not known
          double fill = 0.0, band = 0.0;
          bool ok = true;
          for (const CellRise& r : shape.rises) {
            const double may = remaining[index(r.cell)];
            if (may < 0.0 || r.rise_m > may + overshoot_m || r.rise_m > p.max_height_m) {
              ok = false;
              break;
            }
            fill += std::min(r.rise_m, may) * area;
            if (in_band[index(r.cell)]) band += std::min(r.rise_m, may) * area;
          }
          // Most of the pile must land under the MARS height: material spent above it is lost to the structure.
          if (!ok || fill < kMinFillFraction * v || !(band > best.band_m3 + 1e-12)) continue;
          // The world computes the pile on its own copy of the terrain, in its own frame: a cell at the pile's edge
          // may rise there by rounding. A slightly bigger pile covers every cell this one could (the cells rising
          // grow with the volume), so it must not reach a cell this robot may not raise either.
          const DepositShape guard = cone_pile_shape(heights, dump, v * (1.0 + kGuardFraction), repose_deg_);
          if (!guard.on_grid) continue;
          bool guarded = true;
          for (const CellRise& r : guard.rises)
            if (remaining[index(r.cell)] < 0.0) guarded = false;
          if (!guarded) continue;
          best = {fill, band, dump, v, std::move(shape)};
        }
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
  static constexpr double kMinVolumeM3 = 1e-7;  // smaller piles are not worth a deposit [m^3]
  static constexpr std::size_t kVolumeHalvings = 6;  // volumes tried: the budget, half of it, ... 1/32 of it
  static constexpr double kMinFillFraction = 0.75;
  static constexpr double kGuardFraction = 1e-6;  // the guard pile's extra volume, relative
  double repose_deg_;
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
