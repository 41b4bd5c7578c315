#include "marsala/world_server/rules/arbiter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <utility>

#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/cell_occupancy.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/core/segment_cells.hpp"

namespace marsala::world_server {
namespace {

namespace tol = tolerance;

// A bound on one cube column's count, far above any column within the 1 m per-cell limit: it keeps the count an int.
constexpr long long kMaxCubesPerColumn = 1000000;

double distance(double ax, double ay, double bx, double by) {
  const double dx = ax - bx, dy = ay - by;
  return std::sqrt(dx * dx + dy * dy);
}

/// Rule 4: a refill only at the base; nullopt when it passes.
std::optional<Verdict> check_refill(const WorldState& state, const protocol::ActionRequest& r, double x, double y) {
  if (!r.refill) return std::nullopt;
  const double to_base = distance(x, y, state.base.x_m, state.base.y_m);
  if (to_base <= state.base.radius_m + tol::kLengthM) return std::nullopt;
  return Verdict{false,
                 "refill requested " + fmt::format("{}", to_base) + " m from the base station (radius " +
                     fmt::format("{}", state.base.radius_m) + " m)",
                 4, 0.0, {}};
}

std::string where(const Deposit& d) { return "(" + fmt::format("{}", d.x_m) + ", " + fmt::format("{}", d.y_m) + ")"; }

/// Rule 3 for a cube or cone depositor (docs/runtime.md#rule-3-deposits), judged from (x, y), the position after the
/// motion. The volumes are checked before any shape is computed, so no request costs more than its volume allows.
Verdict validate_deposits(const WorldState& state, const AgentRecord& me, double x, double y,
                          const std::vector<Deposit>& deposits) {
  const auto reject = [](std::string reason) { return Verdict{false, std::move(reason), 3, 0.0, {}}; };
  const Heightmap& terrain = state.terrain;
  const DepositorKind kind = depositor_kind(me.type.depositor.name);
  const double side = depositor_cube_size_m(me.type);
  double volume = 0.0;
  for (const Deposit& d : deposits) {
    const double from_me = distance(d.x_m, d.y_m, x, y);
    if (!(from_me <= me.type.body.reach_m + tol::kLengthM))
      return reject("deposit at " + where(d) + " is " + fmt::format("{}", from_me) + " m away, beyond reach_m " +
                    fmt::format("{}", me.type.body.reach_m));
    if (!(d.volume_m3 > 0.0))
      return reject("deposit volume " + fmt::format("{}", d.volume_m3) + " m^3 at " + where(d) + " is not > 0");
    if (kind == DepositorKind::kCube && whole_cubes(d.volume_m3, side) < 1)
      return reject("deposit volume " + fmt::format("{}", d.volume_m3) + " m^3 at " + where(d) +
                    " is not a whole number of cubes of side " + fmt::format("{}", side) + " m");
    volume += d.volume_m3;
  }
  if (!(volume <= me.type.body.max_deposit_m3 + tol::kVolumeM3))
    return reject("deposited volume " + fmt::format("{}", volume) + " m^3 exceeds max_deposit_m3 " +
                  fmt::format("{}", me.type.body.max_deposit_m3));
  if (!(volume <= me.material_m3 + tol::kVolumeM3))
    return reject("deposited volume " + fmt::format("{}", volume) + " m^3 exceeds the material on board " +
                  fmt::format("{}", me.material_m3) + " m^3");

  // The shapes, in list order: a pile lands on the piles before it in the same request.
  std::optional<Heightmap> after;
  const bool layered = kind == DepositorKind::kCone && deposits.size() > 1;
  if (layered) after = terrain;
  std::map<std::pair<int, int>, double> raised;  // total rise of each cell in this request
  Verdict ok{true, {}, 0, 0.0, {}};
  const double cs = terrain.cell_size_m();
  for (const Deposit& d : deposits) {
    const long long cubes = kind == DepositorKind::kCube ? whole_cubes(d.volume_m3, side) : 0;
    if (cubes > kMaxCubesPerColumn)
      return reject("deposit at " + where(d) + " is a column of " + std::to_string(cubes) + " cubes, more than " +
                    std::to_string(kMaxCubesPerColumn));
    const DepositShape shape =
        kind == DepositorKind::kCube
            ? cube_column_shape(terrain.geometry(), {d.x_m, d.y_m}, side, static_cast<int>(cubes))
            : cone_pile_shape(layered ? *after : terrain, {d.x_m, d.y_m}, d.volume_m3, me.type.depositor.repose_deg);
    if (!shape.on_grid) return reject("deposit at " + where(d) + " would leave the grid");
    for (const CellRise& c : shape.rises) {
      const Position centre = terrain.cell_center(c.cell);
      for (const AgentRecord& other : state.agents) {
        if (!other.alive) continue;
        const bool self = other.id == me.id;
        const double gap = distance(centre.x, centre.y, self ? x : other.x_m, self ? y : other.y_m);
        if (gap <= 0.5 * other.type.body.navigability.delta_m + tol::kLengthM)
          return reject("deposit at " + where(d) + " raises cell " + fmt::format("{}", c.cell) + ", under agent " +
                        std::to_string(other.id));
      }
      double& total = raised[{c.cell.row, c.cell.col}];
      total += c.rise_m;
      if (!(total <= kMaxDepositionM + tol::kLengthM))
        return reject("deposit at " + where(d) + " raises cell " + fmt::format("{}", c.cell) + " by " +
                      fmt::format("{}", total) + " m in this request, more than 1 m");
      if (layered) (*after)(c.cell) += c.rise_m;
      ok.rises.push_back({c.cell.row, c.cell.col, c.rise_m});
      ok.volume_m3 += c.rise_m * cs * cs;
    }
  }
  return ok;
}

}  // namespace

double body_clearance_m(const AgentRecord& a, const AgentRecord& b) {
  return 0.5 * (a.type.body.navigability.delta_m + b.type.body.navigability.delta_m);
}

bool bodies_overlap(const AgentRecord& a, double ax, double ay, const AgentRecord& b, double bx, double by) {
  return distance(ax, ay, bx, by) < body_clearance_m(a, b) - tol::kLengthM;
}

const std::vector<Deposition>& raised_cells(const protocol::ActionRequest& request, const Verdict& verdict) {
  return request.depositions.empty() ? verdict.rises : request.depositions;
}

Verdict validate_request(const WorldState& state, std::uint32_t channel_id, const protocol::ActionRequest& r) {
  int rule = 1;
  const auto reject = [&rule](std::string reason) { return Verdict{false, std::move(reason), rule, 0.0, {}}; };

  // 1. Envelope.
  if (r.agent_id != channel_id)
    return reject("agent_id " + std::to_string(r.agent_id) + " arrived on the partition of agent " +
                  std::to_string(channel_id));
  if (!state.has_agent(channel_id) || !state.agent(channel_id).alive)
    return reject("agent " + std::to_string(channel_id) + " is not admitted and alive");
  const AgentRecord& me = state.agent(channel_id);
  if (r.session != me.session)
    return reject("session " + std::to_string(r.session) + " does not match the admitted session");
  if (r.step != state.step)
    return reject("request for step " + std::to_string(r.step) + " but the current step is " +
                  std::to_string(state.step));
  const auto sane = [](double v) { return std::isfinite(v) && std::abs(v) < 1e6; };
  if (!sane(r.target_x_m) || !sane(r.target_y_m))
    return reject("target (" + fmt::format("{}", r.target_x_m) + ", " + fmt::format("{}", r.target_y_m) +
                  ") is not finite or too large");
  for (const Deposition& d : r.depositions)
    if (!sane(d.height_m))
      return reject("deposition height " + fmt::format("{}", d.height_m) + " m is not finite or too large");
  const Heightmap& terrain = state.terrain;
  if (static_cast<long long>(r.depositions.size()) > terrain.size())
    return reject(std::to_string(r.depositions.size()) + " depositions exceed the grid's cells");
  for (const Deposit& d : r.deposits)
    if (!sane(d.x_m) || !sane(d.y_m) || !sane(d.volume_m3))
      return reject("deposit at (" + fmt::format("{}", d.x_m) + ", " + fmt::format("{}", d.y_m) + ") of " +
                    fmt::format("{}", d.volume_m3) + " m^3 is not finite or too large");
  if (r.deposits.size() > kMaxDeposits)
    return reject(std::to_string(r.deposits.size()) + " deposits exceed the limit of " +
                  std::to_string(kMaxDeposits) + " per request");

  // 2. Motion.
  rule = 2;
  double x = me.x_m, y = me.y_m;
  if (r.move) {
    const double d = distance(r.target_x_m, r.target_y_m, x, y);
    if (!(d <= me.type.body.max_step_m + tol::kLengthM))
      return reject("motion of " + fmt::format("{}", d) + " m exceeds max_step_m " +
                    fmt::format("{}", me.type.body.max_step_m));
    const auto cell = terrain.cell_at({r.target_x_m, r.target_y_m});
    if (!cell)
      return reject("target (" + fmt::format("{}", r.target_x_m) + ", " + fmt::format("{}", r.target_y_m) +
                    ") is off the grid");
    const NavigabilityParams body = me.type.body.navigability;
    if (!cell_occupiable(terrain, *cell, body))
      return reject("target cell " + fmt::format("{}", *cell) + " is not occupiable for this body");
    // The body must be on occupiable terrain all along the way: every cell the segment passes through, except the
    // one it leaves (a robot whose own cell stopped being occupiable may still drive out of it).
    const std::vector<CellIndex> swept = cells_on_segment(terrain.geometry(), {x, y}, {r.target_x_m, r.target_y_m});
    for (std::size_t i = 1; i + 1 < swept.size(); ++i) {
      if (swept[i] == swept.front()) continue;
      if (!terrain.contains(swept[i]) || !cell_occupiable(terrain, swept[i], body))
        return reject("motion passes through cell " + fmt::format("{}", swept[i]) +
                      ", not occupiable for this body");
    }
    // Robot bodies may not overlap where the motion ends: the others stand where this step's lower ids left them
    // and the higher ids where the step found them. Bodies that already overlap (jittered starts, a readmission)
    // may move apart.
    for (const AgentRecord& other : state.agents) {
      if (!other.alive || other.id == me.id) continue;
      if (!bodies_overlap(me, r.target_x_m, r.target_y_m, other, other.x_m, other.y_m)) continue;
      const double after = distance(r.target_x_m, r.target_y_m, other.x_m, other.y_m);
      if (bodies_overlap(me, x, y, other, other.x_m, other.y_m) && after >= distance(x, y, other.x_m, other.y_m))
        continue;
      return reject("motion ends " + fmt::format("{}", after) + " m from agent " + std::to_string(other.id) +
                    ", whose body it would overlap (bodies need " + fmt::format("{}", body_clearance_m(me, other)) +
                    " m)");
    }
    x = r.target_x_m;
    y = r.target_y_m;
  }

  // 3. Depositions, from the position after the motion, by the robot's own depositor.
  rule = 3;
  const DepositorKind kind = depositor_kind(me.type.depositor.name);
  if (kind == DepositorKind::kLayer && !r.deposits.empty())
    return reject("robot type '" + me.type.name + "' has the layer depositor: it sends depositions, not deposits");
  if (kind != DepositorKind::kLayer && !r.depositions.empty())
    return reject("robot type '" + me.type.name + "' has the " + to_string(kind) +
                  " depositor: it sends deposits, not depositions");
  if (kind != DepositorKind::kLayer) {
    Verdict deposits = validate_deposits(state, me, x, y, r.deposits);
    if (!deposits.accepted) return deposits;
    if (const auto refused = check_refill(state, r, x, y)) return *refused;
    return deposits;
  }
  const double cs = terrain.cell_size_m();
  const double layer = cube_layer_m(me.type.body.cube_size_m, cs);
  std::vector<std::pair<int, int>> cells;
  cells.reserve(r.depositions.size());
  double volume = 0.0;
  for (const Deposition& d : r.depositions) {
    const CellIndex c{d.row, d.col};
    if (!terrain.contains(c)) return reject("deposition cell " + fmt::format("{}", c) + " is off the grid");
    cells.emplace_back(d.row, d.col);
    if (!(d.height_m > 0.0 && d.height_m <= kMaxDepositionM + tol::kLengthM))
      return reject("deposition height " + fmt::format("{}", d.height_m) + " m at " + fmt::format("{}", c) +
                    " is not in (0, 1] m");
    const double layers = d.height_m / layer;
    const double whole = std::round(layers);
    if (!(whole >= 1.0 && std::abs(layers - whole) <= tol::kCubeMultiple))
      return reject("deposition height " + fmt::format("{}", d.height_m) + " m at " + fmt::format("{}", c) +
                    " is not a whole multiple of the cube layer " + fmt::format("{}", layer) + " m");
    const Position centre = terrain.cell_center(c);
    const double from_me = distance(centre.x, centre.y, x, y);
    if (!(from_me <= me.type.body.reach_m + tol::kLengthM))
      return reject("deposition cell " + fmt::format("{}", c) + " is " + fmt::format("{}", from_me) +
                    " m away, beyond reach_m " + fmt::format("{}", me.type.body.reach_m));
    for (const AgentRecord& other : state.agents) {
      if (!other.alive) continue;
      const bool self = other.id == me.id;
      const double gap = distance(centre.x, centre.y, self ? x : other.x_m, self ? y : other.y_m);
      if (gap <= 0.5 * other.type.body.navigability.delta_m + tol::kLengthM)
        return reject("deposition cell " + fmt::format("{}", c) + " is under agent " + std::to_string(other.id));
    }
    volume += d.height_m * cs * cs;
  }
  std::sort(cells.begin(), cells.end());
  const auto twice = std::adjacent_find(cells.begin(), cells.end());
  if (twice != cells.end())
    return reject("deposition cell " + fmt::format("{}", CellIndex{twice->first, twice->second}) + " is listed twice");
  if (!(volume <= me.type.body.max_deposit_m3 + tol::kVolumeM3))
    return reject("deposited volume " + fmt::format("{}", volume) + " m^3 exceeds max_deposit_m3 " +
                  fmt::format("{}", me.type.body.max_deposit_m3));
  if (!(volume <= me.material_m3 + tol::kVolumeM3))
    return reject("deposited volume " + fmt::format("{}", volume) + " m^3 exceeds the material on board " +
                  fmt::format("{}", me.material_m3) + " m^3");

  if (const auto refused = check_refill(state, r, x, y)) return *refused;
  return Verdict{true, {}, 0, volume, {}};
}

void apply_request(WorldState& state, const protocol::ActionRequest& r, const Verdict& verdict,
                   std::vector<CellIndex>& changed_cells) {
  AgentRecord& me = state.agent(r.agent_id);
  if (r.move) {
    // docs/runtime.md#heading: the direction of the last motion of non-zero length.
    const double dx = r.target_x_m - me.x_m, dy = r.target_y_m - me.y_m;
    if (dx != 0.0 || dy != 0.0) me.heading_rad = std::atan2(dy, dx);
    me.x_m = r.target_x_m;
    me.y_m = r.target_y_m;
  }
  if ((!r.depositions.empty() || !verdict.rises.empty()) &&
      (state.depositor.rows() != state.terrain.rows() || state.depositor.cols() != state.terrain.cols()))
    state.depositor =
        AgentIdGrid::Zero(state.terrain.rows(), state.terrain.cols());  // a state not made by make_world_state
  for (const Deposition& d : raised_cells(r, verdict)) {
    state.terrain(d.row, d.col) += d.height_m;
    state.depositor(d.row, d.col) = r.agent_id;
    changed_cells.push_back({d.row, d.col});
  }
  me.z_m = height_under(state.terrain, me.x_m, me.y_m);
  me.material_m3 = std::max(0.0, me.material_m3 - verdict.volume_m3);
  if (r.refill) me.material_m3 = me.type.body.material_capacity_m3;
  me.deposited_m3 += verdict.volume_m3;
  state.deposited_volume_m3 += verdict.volume_m3;
  ++me.accepted;
}

}  // namespace marsala::world_server
