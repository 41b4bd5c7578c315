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
  const double to_base = distance(x, y, state.base.centre.x, state.base.centre.y);
  if (to_base <= state.base.radius_m + tol::kLengthM) return std::nullopt;
  return Verdict{false,
                 fmt::format("refill requested {} m from the base station (radius {} m)", to_base,
                             state.base.radius_m),
                 4, 0.0, {}};
}

Position at(const Deposit& d) { return d.centre; }

/// Rule 3's bounds on the volume of one request, from its body and the material on board; nullopt when it passes.
std::optional<std::string> volume_problem(const AgentRecord& me, double volume) {
  if (!(volume <= me.type.body.max_deposit_m3 + tol::kVolumeM3))
    return fmt::format("deposited volume {} m^3 exceeds max_deposit_m3 {}", volume, me.type.body.max_deposit_m3);
  if (!(volume <= me.material_m3 + tol::kVolumeM3))
    return fmt::format("deposited volume {} m^3 exceeds the material on board {} m^3", volume, me.material_m3);
  return std::nullopt;
}

/// The first live agent (by id) whose body centre lies within half its delta of `centre` (`me` taken at (x, y)).
const AgentRecord* agent_over(const WorldState& state, const AgentRecord& me, double x, double y, Position centre) {
  for (const AgentRecord& other : state.agents) {
    if (!other.alive) continue;
    const bool self = other.id == me.id;
    const double gap = distance(centre.x, centre.y, self ? x : other.position.x, self ? y : other.position.y);
    if (gap <= 0.5 * other.type.body.navigability.delta_m + tol::kLengthM) return &other;
  }
  return nullptr;
}

/// Rules 3.5b and 3d.10 (docs/runtime.md#deposit-bound): what `me` deposits may leave `cell` at `height_m` [m] only
/// up to the deposit bound plus kDepositOvershootFraction of `me`'s construction eps; nullopt when it passes (or the
/// state has no bound). The reason names `deposit`, or "deposition" (a layer robot's) when it is null.
std::optional<std::string> bound_problem(const WorldState& state, const AgentRecord& me, const Deposit* deposit,
                                         CellIndex cell, double height_m) {
  if (state.deposit_bound.rows() != state.terrain.rows() || state.deposit_bound.cols() != state.terrain.cols())
    return std::nullopt;
  const double bound = state.deposit_bound(cell);
  const double allowed = kDepositOvershootFraction * construction_params(me.type).eps_m;
  if (height_m <= bound + allowed + tol::kLengthM) return std::nullopt;
  return fmt::format(
      "{} would leave cell {} at {} m, {} m above the deposit bound {} m (MARS of the initial terrain at kappa {}), "
      "more than {} m",
      deposit ? fmt::format("deposit at {}", at(*deposit)) : std::string("deposition"), cell, height_m,
      height_m - bound, bound, state.deposit_bound_kappa, allowed);
}

/// Rule 3 for a cube or cone depositor (docs/runtime.md#rule-3-deposits), judged from (x, y), the position after the
/// motion. The volumes are checked before any shape is computed, so no request costs more than its volume allows.
Verdict validate_deposits(const WorldState& state, const AgentRecord& me, double x, double y,
                          const std::vector<Deposit>& deposits) {
  const auto reject = [](std::string reason) { return Verdict{false, std::move(reason), 3, 0.0, {}}; };
  const Heightmap& terrain = state.terrain;
  const DepositorKind kind = me.type.depositor.kind;
  const double side = depositor_cube_size_m(me.type);
  double volume = 0.0;
  for (const Deposit& d : deposits) {
    const double from_me = distance(d.centre.x, d.centre.y, x, y);
    if (!(from_me <= me.type.body.reach_m + tol::kLengthM))
      return reject(fmt::format("deposit at {} is {} m away, beyond reach_m {}", at(d), from_me, me.type.body.reach_m));
    if (!(d.volume_m3 > 0.0)) return reject(fmt::format("deposit volume {} m^3 at {} is not > 0", d.volume_m3, at(d)));
    if (kind == DepositorKind::kCube && whole_cubes(d.volume_m3, side) < 1)
      return reject(fmt::format("deposit volume {} m^3 at {} is not a whole number of cubes of side {} m", d.volume_m3,
                                at(d), side));
    volume += d.volume_m3;
  }
  if (auto problem = volume_problem(me, volume)) return reject(std::move(*problem));

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
      return reject(
          fmt::format("deposit at {} is a column of {} cubes, more than {}", at(d), cubes, kMaxCubesPerColumn));
    const DepositShape shape =
        kind == DepositorKind::kCube
            ? cube_column_shape(terrain.geometry(), d.centre, side, static_cast<int>(cubes))
            : cone_pile_shape(layered ? *after : terrain, d.centre, d.volume_m3, me.type.depositor.repose_deg);
    if (!shape.on_grid) return reject(fmt::format("deposit at {} would leave the grid", at(d)));
    for (const CellRise& c : shape.rises) {
      if (const AgentRecord* other = agent_over(state, me, x, y, terrain.cell_center(c.cell)))
        return reject(fmt::format("deposit at {} raises cell {}, under agent {}", at(d), c.cell, other->id));
      double& total = raised[{c.cell.row, c.cell.col}];
      total += c.rise_m;
      if (!(total <= kMaxDepositionM + tol::kLengthM))
        return reject(
            fmt::format("deposit at {} raises cell {} by {} m in this request, more than 1 m", at(d), c.cell, total));
      if (auto problem = bound_problem(state, me, &d, c.cell, terrain(c.cell) + total))
        return reject(std::move(*problem));
      if (layered) (*after)(c.cell) += c.rise_m;
      ok.rises.push_back({c.cell.row, c.cell.col, c.rise_m});
      ok.volume_m3 += c.rise_m * cs * cs;
    }
  }
  return ok;
}

/// Rule 3 for the layer depositor (docs/runtime.md#rule-3-depositions), judged from (x, y).
Verdict validate_depositions(const WorldState& state, const AgentRecord& me, double x, double y,
                             const std::vector<Deposition>& depositions) {
  const auto reject = [](std::string reason) { return Verdict{false, std::move(reason), 3, 0.0, {}}; };
  const Heightmap& terrain = state.terrain;
  const double cs = terrain.cell_size_m();
  const double layer = cube_layer_m(me.type.body.cube_size_m, cs);
  std::vector<std::pair<int, int>> cells;
  cells.reserve(depositions.size());
  double volume = 0.0;
  for (const Deposition& d : depositions) {
    const CellIndex c{d.row, d.col};
    if (!terrain.contains(c)) return reject(fmt::format("deposition cell {} is off the grid", c));
    cells.emplace_back(d.row, d.col);
    if (!(d.height_m > 0.0 && d.height_m <= kMaxDepositionM + tol::kLengthM))
      return reject(fmt::format("deposition height {} m at {} is not in (0, 1] m", d.height_m, c));
    const double layers = d.height_m / layer;
    const double whole = std::round(layers);
    if (!(whole >= 1.0 && std::abs(layers - whole) <= tol::kCubeMultiple))
      return reject(fmt::format("deposition height {} m at {} is not a whole multiple of the cube layer {} m",
                                d.height_m, c, layer));
    const Position centre = terrain.cell_center(c);
    const double from_me = distance(centre.x, centre.y, x, y);
    if (!(from_me <= me.type.body.reach_m + tol::kLengthM))
      return reject(
          fmt::format("deposition cell {} is {} m away, beyond reach_m {}", c, from_me, me.type.body.reach_m));
    if (const AgentRecord* other = agent_over(state, me, x, y, centre))
      return reject(fmt::format("deposition cell {} is under agent {}", c, other->id));
    if (auto problem = bound_problem(state, me, nullptr, c, terrain(c) + d.height_m))
      return reject(std::move(*problem));
    volume += d.height_m * cs * cs;
  }
  std::sort(cells.begin(), cells.end());
  const auto twice = std::adjacent_find(cells.begin(), cells.end());
  if (twice != cells.end())
    return reject(fmt::format("deposition cell {} is listed twice", CellIndex{twice->first, twice->second}));
  if (auto problem = volume_problem(me, volume)) return reject(std::move(*problem));
  return Verdict{true, {}, 0, volume, {}};
}

/// Rule 1, the envelope (docs/runtime.md#rule-1-envelope): identity, session, step and sane numbers; nullopt when
/// it passes.
std::optional<std::string> envelope_problem(const WorldState& state, std::uint32_t channel_id,
                                            const protocol::ActionRequest& r) {
  if (r.agent_id != channel_id)
    return fmt::format("agent_id {} arrived on the partition of agent {}", r.agent_id, channel_id);
  if (!state.has_agent(channel_id) || !state.agent(channel_id).alive)
    return fmt::format("agent {} is not admitted and alive", channel_id);
  if (r.session != state.agent(channel_id).session)
    return fmt::format("session {} does not match the admitted session", r.session);
  if (r.step != state.step) return fmt::format("request for step {} but the current step is {}", r.step, state.step);
  const auto sane = [](double v) { return std::isfinite(v) && std::abs(v) < 1e6; };
  if (!sane(r.target_x_m) || !sane(r.target_y_m))
    return fmt::format("target {} is not finite or too large", Position{r.target_x_m, r.target_y_m});
  for (const Deposition& d : r.depositions)
    if (!sane(d.height_m)) return fmt::format("deposition height {} m is not finite or too large", d.height_m);
  if (static_cast<long long>(r.depositions.size()) > state.terrain.size())
    return fmt::format("{} depositions exceed the grid's cells", r.depositions.size());
  for (const Deposit& d : r.deposits)
    if (!sane(d.centre.x) || !sane(d.centre.y) || !sane(d.volume_m3))
      return fmt::format("deposit at {} of {} m^3 is not finite or too large", at(d), d.volume_m3);
  if (r.deposits.size() > kMaxDeposits)
    return fmt::format("{} deposits exceed the limit of {} per request", r.deposits.size(), kMaxDeposits);
  return std::nullopt;
}

/// What a body that tried to stand on `cell` would feel (docs/runtime.md#refused-requests): ": cell (r, c) at h m lies
/// too far below cell (r, c) at h m", the worst pair, then "; cell (r, c) at h m lies too far below cell (r, c) at h m"
/// for each other cell of the ball that breaks the rule (kMaxNamedDrops in all at most, the most first), or nothing
/// when the cell is occupiable.
std::string breach_of(const Heightmap& terrain, CellIndex cell, const NavigabilityParams& body) {
  const std::vector<OccupancyBreach> breaches = occupancy_breaches(terrain, cell, body);
  std::string out;
  for (std::size_t i = 0; i < breaches.size() && i < kMaxNamedDrops; ++i)
    out += fmt::format("{} cell {} at {} m lies too far below cell {} at {} m", i == 0 ? ":" : ";", breaches[i].low,
                       terrain(breaches[i].low), breaches[i].high, terrain(breaches[i].high));
  return out;
}

/// Rule 2, the motion of `me` to the request's target (docs/runtime.md#rule-2-motion); nullopt when it passes.
std::optional<std::string> motion_problem(const WorldState& state, const AgentRecord& me,
                                          const protocol::ActionRequest& r) {
  const Heightmap& terrain = state.terrain;
  const double x = me.position.x, y = me.position.y;
  const double d = distance(r.target_x_m, r.target_y_m, x, y);
  if (!(d <= me.type.body.max_step_m + tol::kLengthM))
    return fmt::format("motion of {} m exceeds max_step_m {}", d, me.type.body.max_step_m);
  const auto cell = terrain.cell_at({r.target_x_m, r.target_y_m});
  if (!cell) return fmt::format("target {} is off the grid", Position{r.target_x_m, r.target_y_m});
  const NavigabilityParams body = me.type.body.navigability;
  if (!cell_occupiable(terrain, *cell, body))
    return fmt::format("target cell {} is not occupiable for this body{}", *cell, breach_of(terrain, *cell, body));
  // The body must be on occupiable terrain all along the way: every cell the segment passes through, except the
  // one it leaves (a robot whose own cell stopped being occupiable may still drive out of it).
  const std::vector<CellIndex> swept = cells_on_segment(terrain.geometry(), {x, y}, {r.target_x_m, r.target_y_m});
  for (std::size_t i = 1; i + 1 < swept.size(); ++i) {
    if (swept[i] == swept.front()) continue;
    if (!terrain.contains(swept[i]) || !cell_occupiable(terrain, swept[i], body))
      return fmt::format("motion passes through cell {}, not occupiable for this body{}", swept[i],
                         terrain.contains(swept[i]) ? breach_of(terrain, swept[i], body) : std::string());
  }
  // Robot bodies may not overlap where the motion ends: the others stand where this step's lower ids left them
  // and the higher ids where the step found them. Bodies that already overlap (jittered starts, a readmission)
  // may move apart.
  for (const AgentRecord& other : state.agents) {
    if (!other.alive || other.id == me.id) continue;
    if (!bodies_overlap(me, r.target_x_m, r.target_y_m, other, other.position.x, other.position.y)) continue;
    const double after = distance(r.target_x_m, r.target_y_m, other.position.x, other.position.y);
    if (bodies_overlap(me, x, y, other, other.position.x, other.position.y) &&
        after >= distance(x, y, other.position.x, other.position.y))
      continue;
    return fmt::format("motion ends {} m from agent {}, whose body it would overlap (bodies need {} m)", after,
                       other.id, body_clearance_m(me, other));
  }
  return std::nullopt;
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
  const auto reject = [](int rule, std::string reason) { return Verdict{false, std::move(reason), rule, 0.0, {}}; };
  if (auto problem = envelope_problem(state, channel_id, r)) return reject(1, std::move(*problem));
  const AgentRecord& me = state.agent(channel_id);
  double x = me.position.x, y = me.position.y;
  if (r.move) {
    if (auto problem = motion_problem(state, me, r)) return reject(2, std::move(*problem));
    x = r.target_x_m;
    y = r.target_y_m;
  }
  // 3. Depositions, from the position after the motion, by the robot's own depositor.
  const DepositorKind kind = me.type.depositor.kind;
  if (kind == DepositorKind::kLayer && !r.deposits.empty())
    return reject(3, fmt::format("robot type '{}' has the layer depositor: it sends depositions, not deposits",
                                 me.type.name));
  if (kind != DepositorKind::kLayer && !r.depositions.empty())
    return reject(3, fmt::format("robot type '{}' has the {} depositor: it sends deposits, not depositions",
                                 me.type.name, to_string(kind)));
  Verdict verdict = kind == DepositorKind::kLayer ? validate_depositions(state, me, x, y, r.depositions)
                                                  : validate_deposits(state, me, x, y, r.deposits);
  if (!verdict.accepted) return verdict;
  if (const auto refused = check_refill(state, r, x, y)) return *refused;
  return verdict;
}

void apply_request(WorldState& state, const protocol::ActionRequest& r, const Verdict& verdict,
                   std::vector<CellIndex>& changed_cells) {
  AgentRecord& me = state.agent(r.agent_id);
  if (r.move) {
    // docs/runtime.md#heading: the direction of the last motion of non-zero length.
    const double dx = r.target_x_m - me.position.x, dy = r.target_y_m - me.position.y;
    if (dx != 0.0 || dy != 0.0) me.heading_rad = std::atan2(dy, dx);
    me.position.x = r.target_x_m;
    me.position.y = r.target_y_m;
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
  me.z_m = height_under(state.terrain, me.position.x, me.position.y);
  me.material_m3 = std::max(0.0, me.material_m3 - verdict.volume_m3);
  if (r.refill) me.material_m3 = me.type.body.material_capacity_m3;
  me.deposited_m3 += verdict.volume_m3;
  state.deposited_volume_m3 += verdict.volume_m3;
  ++me.accepted;
}

}  // namespace marsala::world_server
