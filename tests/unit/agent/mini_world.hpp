#pragma once
// A small stand-in for the world server, written from docs/runtime.md alone (not from the agent's code): the
// authoritative terrain, admission, sensor frames (tiles in range that changed since the agent last got them,
// neighbours in range) and the validation rules of an ActionRequest. Closed-loop agent tests drive real
// behaviours with it and check that every request they make is one the world accepts.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/core/segment_cells.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::agent::test {

/// One robot as the mini world sees it.
struct MiniRobot {
  std::uint32_t id = 0;
  std::uint64_t session = 0;
  RobotBody body;
  Position pos;
  Position target;
  double material_m3 = 0.0;
  protocol::ActionResult last_result = protocol::ActionResult::kNone;
  std::string last_reason;
  std::map<std::pair<int, int>, std::uint64_t> tiles_seen;  // tile -> version last sent
  double deposited_m3 = 0.0;
  int accepted = 0;
  int rejected = 0;
};

class MiniWorld {
 public:
  MiniWorld(Heightmap terrain, int tile_size, Position base, double base_radius_m)
      : terrain_(std::move(terrain)), tile_size_(tile_size), base_(base), base_radius_m_(base_radius_m) {
    tile_rows_ = (terrain_.rows() + tile_size - 1) / tile_size;
    tile_cols_ = (terrain_.cols() + tile_size - 1) / tile_size;
    tile_version_.assign(static_cast<std::size_t>(tile_rows_) * tile_cols_, 1);
  }

  const Heightmap& terrain() const { return terrain_; }
  std::uint64_t step() const { return step_; }
  const std::map<std::uint32_t, MiniRobot>& robots() const { return robots_; }
  const MiniRobot& robot(std::uint32_t id) const { return robots_.at(id); }

  /// Admits robot `id` at `start` heading for `target` with a full load.
  protocol::Admission admit(std::uint32_t id, std::uint64_t session, const RobotBody& body, Position start,
                            Position target) {
    MiniRobot r;
    r.id = id;
    r.session = session;
    r.body = body;
    r.pos = start;
    r.target = target;
    r.material_m3 = body.material_capacity_m3;
    robots_[id] = r;
    protocol::Admission a;
    a.agent_id = id;
    a.session = session;
    a.accepted = true;
    a.run_id = "mini";
    a.assignment.world.rows = terrain_.rows();
    a.assignment.world.cols = terrain_.cols();
    a.assignment.world.xll_m = terrain_.geometry().xll_m;
    a.assignment.world.yll_m = terrain_.geometry().yll_m;
    a.assignment.world.cell_size_m = terrain_.cell_size_m();
    a.assignment.tile_size = tile_size_;
    a.assignment.start.x = start.x;
    a.assignment.start.y = start.y;
    a.assignment.target.x = target.x;
    a.assignment.target.y = target.y;
    a.assignment.base.x = base_.x;
    a.assignment.base.y = base_.y;
    a.assignment.base_radius_m = base_radius_m_;
    return a;
  }

  /// The frame of robot `id` for the current step: tiles meeting its sensing square that changed since it last
  /// got them, neighbours within proximity range.
  protocol::SensorFrame frame_for(std::uint32_t id, bool run_over = false) {
    MiniRobot& r = robots_.at(id);
    protocol::SensorFrame f;
    f.agent_id = id;
    f.step = step_;
    f.x_m = r.pos.x;
    f.y_m = r.pos.y;
    f.z_m = terrain_(*terrain_.cell_at(r.pos));
    f.material_m3 = r.material_m3;
    f.last_result = r.last_result;
    f.last_reason = r.last_reason;
    f.run_over = run_over;
    const double range = r.body.sensing_range_m, cs = terrain_.cell_size_m();
    const auto& g = terrain_.geometry();
    const int col_lo = clamp(static_cast<int>(std::floor((r.pos.x - range - g.xll_m) / cs)), 0, g.cols - 1);
    const int col_hi = clamp(static_cast<int>(std::floor((r.pos.x + range - g.xll_m) / cs)), 0, g.cols - 1);
    const int south_lo = clamp(static_cast<int>(std::floor((r.pos.y - range - g.yll_m) / cs)), 0, g.rows - 1);
    const int south_hi = clamp(static_cast<int>(std::floor((r.pos.y + range - g.yll_m) / cs)), 0, g.rows - 1);
    const int row_lo = g.rows - 1 - south_hi, row_hi = g.rows - 1 - south_lo;
    for (int tr = row_lo / tile_size_; tr <= row_hi / tile_size_; ++tr)
      for (int tc = col_lo / tile_size_; tc <= col_hi / tile_size_; ++tc) {
        const std::uint64_t v = tile_version_[static_cast<std::size_t>(tr) * tile_cols_ + tc];
        auto& seen = r.tiles_seen[{tr, tc}];
        if (seen == v) continue;
        seen = v;
        TerrainTile t;
        t.tile_row = tr;
        t.tile_col = tc;
        t.rows = std::min(tile_size_, g.rows - tr * tile_size_);
        t.cols = std::min(tile_size_, g.cols - tc * tile_size_);
        for (int i = 0; i < t.rows; ++i)
          for (int j = 0; j < t.cols; ++j) t.heights.push_back(terrain_(tr * tile_size_ + i, tc * tile_size_ + j));
        f.tiles.push_back(std::move(t));
      }
    for (const auto& [oid, o] : robots_)
      if (oid != id && std::hypot(o.pos.x - r.pos.x, o.pos.y - r.pos.y) <= r.body.proximity_range_m)
        f.neighbours.push_back(
            {oid, o.pos.x, o.pos.y, terrain_(*terrain_.cell_at(o.pos)), o.body.navigability.delta_m / 2.0});
    return f;
  }

  /// Why the world would reject `q` in the current state ("" when it accepts it), per docs/runtime.md#validation.
  std::string validate(const protocol::ActionRequest& q) const {
    const auto it = robots_.find(q.agent_id);
    if (it == robots_.end()) return "unknown agent";
    const MiniRobot& r = it->second;
    if (q.session != r.session) return "wrong session";
    if (q.step != step_) return "wrong step";
    const RobotBody& b = r.body;
    const double cs = terrain_.cell_size_m();
    for (double v : {q.target_x_m, q.target_y_m})
      if (!std::isfinite(v) || std::abs(v) >= 1e6) return "bad number";
    Position pos = r.pos;
    if (q.move) {
      const Position t{q.target_x_m, q.target_y_m};
      const double d = std::hypot(t.x - r.pos.x, t.y - r.pos.y);
      if (d > b.max_step_m + 1e-9) return "motion of " + num(d) + " m exceeds max_step";
      const auto cell = terrain_.cell_at(t);
      if (!cell) return "motion target off the grid";
      const CellMask occ = NavigabilityProcessor({b.navigability.kappa, b.navigability.delta_m, b.navigability.eps_m})
                               .occupiable(terrain_);
      if (occ(cell->row, cell->col) == 0) return "motion target cell not occupiable";
      const std::vector<CellIndex> swept = cells_on_segment(terrain_.geometry(), r.pos, t);
      for (std::size_t i = 1; i < swept.size(); ++i)
        if (swept[i] != swept.front() && occ(swept[i].row, swept[i].col) == 0)
          return "motion passes through a cell not occupiable";
      for (const auto& [oid, o] : robots_) {  // rule 2.5: bodies may not come to overlap
        if (oid == q.agent_id) continue;
        const double need = (b.navigability.delta_m + o.body.navigability.delta_m) / 2.0 - 1e-9;
        const double after = std::hypot(t.x - o.pos.x, t.y - o.pos.y);
        const double before = std::hypot(r.pos.x - o.pos.x, r.pos.y - o.pos.y);
        if (after < need && !(before < need && after >= before))
          return "motion ends overlapping robot " + std::to_string(oid);
      }
      pos = t;
    }
    const double q_layer = b.cube_size_m * b.cube_size_m * b.cube_size_m / (cs * cs);
    std::set<std::pair<int, int>> cells;
    double volume = 0.0;
    for (const auto& d : q.depositions) {
      const CellIndex c{d.row, d.col};
      if (!terrain_.contains(c)) return "deposition off the grid";
      if (!cells.insert({d.row, d.col}).second) return "cell listed twice";
      if (!std::isfinite(d.height_m) || !(d.height_m > 0.0) || d.height_m > 1.0 + 1e-9)
        return "deposition height " + num(d.height_m) + " out of (0, 1] m";
      const double n = d.height_m / q_layer;
      if (std::abs(n - std::round(n)) > 1e-6 || std::round(n) < 1) return "not a whole number of cube layers";
      const Position centre = terrain_.cell_center(c);
      if (std::hypot(centre.x - pos.x, centre.y - pos.y) > b.reach_m + 1e-9) return "deposition out of reach";
      for (const auto& [oid, o] : robots_) {
        const Position p = oid == q.agent_id ? pos : o.pos;
        if (!(std::hypot(centre.x - p.x, centre.y - p.y) > o.body.navigability.delta_m / 2.0))
          return "deposition under robot " + std::to_string(oid);
      }
      volume += d.height_m * cs * cs;
    }
    if (volume > b.max_deposit_m3 + 1e-12) return "volume " + num(volume) + " over the deposition threshold";
    if (volume > r.material_m3 + 1e-12) return "volume " + num(volume) + " over the material on board";
    if (q.refill && std::hypot(pos.x - base_.x, pos.y - base_.y) > base_radius_m_ + 1e-9)
      return "refill away from the base";
    return "";
  }

  /// Validates and applies the requests in id order, each against the state left by the previous ones; returns
  /// the reasons of rejected ones ("" for accepted), in the same order. Then advances the step.
  std::vector<std::string> apply_step(std::vector<protocol::ActionRequest> requests) {
    std::sort(requests.begin(), requests.end(), [](const auto& a, const auto& b) { return a.agent_id < b.agent_id; });
    std::vector<std::string> reasons;
    for (const auto& q : requests) {
      MiniRobot& r = robots_.at(q.agent_id);
      const std::string why = validate(q);
      reasons.push_back(why);
      r.last_result = why.empty() ? protocol::ActionResult::kAccepted : protocol::ActionResult::kRejected;
      r.last_reason = why;
      if (!why.empty()) {
        ++r.rejected;
        continue;
      }
      ++r.accepted;
      if (q.move) r.pos = {q.target_x_m, q.target_y_m};
      const double cs = terrain_.cell_size_m();
      for (const auto& d : q.depositions) {
        terrain_(d.row, d.col) += d.height_m;
        r.material_m3 -= d.height_m * cs * cs;
        r.deposited_m3 += d.height_m * cs * cs;
        ++tile_version_[static_cast<std::size_t>(d.row / tile_size_) * tile_cols_ + d.col / tile_size_];
      }
      if (q.refill) r.material_m3 = r.body.material_capacity_m3;
    }
    ++step_;
    return reasons;
  }

 private:
  static int clamp(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }
  static std::string num(double v) {
    std::ostringstream s;
    s.precision(17);
    s << v;
    return s.str();
  }

  Heightmap terrain_;
  int tile_size_;
  int tile_rows_ = 0, tile_cols_ = 0;
  std::vector<std::uint64_t> tile_version_;
  Position base_;
  double base_radius_m_;
  std::map<std::uint32_t, MiniRobot> robots_;
  std::uint64_t step_ = 0;
};

}  // namespace marsala::agent::test
