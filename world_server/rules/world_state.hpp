#pragma once
// The world's authoritative state: terrain, agents, the step counter and per-tile change versions.
// Plain data; the arbiter, apply_step, sensing and completion read and change it. No IO, no clock.

#include <cstdint>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/robot_type.hpp"
#include "marsala/core/types.hpp"
#include "marsala/protocol/messages.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/world_server/rules/occupancy_cache.hpp"
#include "marsala/world_server/rules/stall_watch.hpp"
#include "marsala/world_server/rules/tile_layout.hpp"

namespace marsala::world_server {

/// One agent slot as the world sees it.
struct AgentRecord {
  std::uint32_t id = 0;  ///< >= 1
  RobotType type;        ///< its slot's robot type: body (what the hello must declare), behaviour, name
  Position start;   ///< [m]
  Position target;  ///< [m]

  bool admitted = false;
  bool alive = false;  ///< admitted and not dropped: takes part in the lockstep
  bool dropped = false;
  std::string drop_reason;
  std::uint32_t readmissions = 0;  ///< times it took its slot back after a drop (admission.hpp)
  std::uint64_t session = 0;       ///< from the admitted hello
  std::string name;                ///< from the admitted hello

  Position position;            ///< [m]
  double z_m = 0.0;             ///< terrain height of the cell under the centre [m]
  double material_m3 = 0.0;     ///< material on board [m^3]
  /// Direction the robot faces [rad from east, counter-clockwise]: of its last accepted motion of non-zero length,
  /// initially towards its target (docs/runtime.md#heading). The rgbd sensor looks along it.
  double heading_rad = 0.0;

  std::uint32_t accepted = 0;  ///< requests accepted
  std::uint32_t rejected = 0;  ///< requests rejected (duplicates and future steps included)
  std::uint32_t missed = 0;    ///< steps without a request
  std::uint32_t consecutive_missed = 0;
  std::uint16_t recent_misses = 0;  ///< bit i set: missed the deadline of the step i steps ago (kMissWindowSteps)
  double deposited_m3 = 0.0;        ///< material placed [m^3]
  bool at_goal = false;
  std::string state;  ///< the behaviour's state from its latest request
  std::string waiting_for;  ///< what its latest request said it waits for, bounded and printable (step.hpp)

  protocol::ActionResult last_result = protocol::ActionResult::kNone;  ///< for its next frame
  std::string last_reason;
};

/// The heading of a robot that has not moved yet: from its start towards its target, 0 (east) when they coincide
/// [rad] (docs/runtime.md#heading).
double initial_heading_rad(const AgentRecord& a);

/// True when `r` carries the agent's admitted identity (id and session): only such a request can answer for it in a
/// step. A request with another identity on its partition is forged or stale and never takes its slot.
inline bool carries_identity_of(const AgentRecord& agent, const protocol::ActionRequest& r) {
  return r.agent_id == agent.id && r.session == agent.session;
}

/// Per-cell agent ids, row-major like the terrain (0 = none).
using AgentIdGrid = Eigen::Matrix<std::uint32_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The payload's route as planned on the initial terrain and what it takes to build it (docs/runtime.md#progress): the
/// cells the payload covers along it (its band) and the MARS bound of the initial terrain at the payload's kappa on
/// each. Filling the band up to that bound makes every route cell occupiable for the payload, so the gap left there
/// falls to 0 as the path is built, and no later than the path is found.
struct RouteGap {
  std::vector<CellIndex> route;       ///< from the cell of `from` to the cell of `to`, 8-connected
  std::vector<std::int64_t> cells;    ///< the band: cells within delta/2 of a route cell, row-major indexes, ascending
  std::vector<double> ceiling_m;      ///< per band cell: P_kappa of the initial terrain [m]
  double initial_m3 = 0.0;            ///< the gap over the band on the initial terrain [m^3]
};

/// The terrain check of payload-path and level-site runs (completion.hpp): its cache and its latest answer.
struct CompletionCheck {
  OccupancyCache occupancy;  ///< payload: the whole grid for the payload's body; site: the site's cells
  CellIndex from;            ///< payload: the cells of `from` and `to`
  CellIndex to;
  bool met = false;               ///< the latest evaluation: completed (payload: path and target kept) / level site
  bool path_found = false;        ///< payload: the latest evaluation found the payload's path
  double target_initial_m = 0.0;  ///< payload: height of the cell of `to` on the initial terrain [m]
  double max_target_rise_m = 0.0; ///< payload: how far that cell may end above it: one cube layer [m]
  double level_fraction = 0.0;    ///< site: the latest level fraction [0, 1]
  std::uint32_t evaluations = 0;  ///< evaluations run, the initial one included
  RouteGap route;                 ///< payload: its route on the initial terrain and the MARS bound over its band
  double route_gap_m3 = 0.0;      ///< payload: the MARS gap left on the route's band at the latest evaluation [m^3]
};

/// Everything the step function reads and changes.
struct WorldState {
  Heightmap terrain;                ///< authoritative heights [m]
  std::vector<AgentRecord> agents;  ///< agents[i].id == i + 1, one per expected agent
  std::uint64_t step = 0;           ///< the step whose requests are awaited
  std::uint64_t seed = 1;           ///< the scenario's seed: seeds the sensors' noise (scan_seed())
  scenario::Goal goal;
  scenario::BaseStation base;
  int tile_size = 16;                        ///< [cells]
  std::vector<std::uint64_t> tile_versions;  ///< per tile (TileLayout index): bumped in every step that changes it
  double deposited_volume_m3 = 0.0;          ///< total placed [m^3]
  scenario::CompletionKind completion = scenario::CompletionKind::kAgentsAtGoal;
  scenario::PayloadPath payload_path;         ///< kPayloadPath: the payload's body, from, to, schedule
  scenario::Site site;                        ///< kLevelSite: the site, its parameters, schedule
  CompletionCheck check;                      ///< kPayloadPath and kLevelSite
  AgentIdGrid depositor;                      ///< per cell: the agent whose deposition last raised it (0 = never)
  std::uint64_t idle_steps = 0;               ///< applied steps in which no deposition was accepted
  std::uint32_t unattributed_rejections = 0;  ///< rejected requests carrying no admitted identity (forged)
  std::uint32_t surplus_requests = 0;         ///< requests beyond a partition's per-step limit, never applied (runtime)
  std::uint32_t resumes = 0;                  ///< times the world was resumed from its run log
  std::uint64_t close_passes = 0;        ///< pairs of robots whose bodies began to overlap in a step [count]
  std::uint64_t overlap_pair_steps = 0;  ///< (step, pair) with overlapping bodies after the step [count]
  std::uint32_t rejected_motions = 0;    ///< requests rejected by a motion rule (docs/runtime.md#rule-2-motion)
  std::uint64_t stall_steps = 0;         ///< the scenario's: quiet steps after which the run stalls; 0 never [steps]
  StallWatch stall;                      ///< progress and terrain activity, for the stall detector
  /// The highest any deposit may leave a cell (docs/runtime.md#deposit-bound): the MARS bound of the initial terrain
  /// at deposit_bound_kappa, computed once by world_state_at(), so the team's own deposits cannot raise it. Empty
  /// when the team has no cube or cone robot, or in a state not made by world_state_at(): no bound is checked [m].
  Heightmap deposit_bound;
  double deposit_bound_kappa = 0.0;  ///< the smallest construction kappa of the team's robot types [m/m]

  /// True when `id` names an agent slot of this run.
  bool has_agent(std::uint32_t id) const { return id >= 1 && id <= agents.size(); }
  /// The record of agent `id`; throws InvalidArgument when there is no such slot.
  AgentRecord& agent(std::uint32_t id);
  const AgentRecord& agent(std::uint32_t id) const;
  /// Ids of the live agents, ascending.
  std::vector<std::uint32_t> live_ids() const;
  /// The tile layout of the terrain.
  TileLayout tiles() const { return TileLayout(terrain.geometry(), tile_size); }
};

/// Throws InvalidArgument unless 1 <= agent_count <= the scenario's agent slots.
void check_agent_count(const scenario::Scenario& scenario, std::uint32_t agent_count);

/// The state before its first step, from starts decided above this unit (initial_state.hpp: start jitter,
/// completion check): `terrain`, the scenario's goal, base, tile size and completion (its check not set up yet), and
/// slots 1..starts.size() (none admitted), slot i + 1 at starts[i] [m]. Throws InvalidArgument when starts.size() is 0
/// or exceeds the scenario's slots, or when a cube depositor is narrower than a cell. When a slot's robot has a cube or
/// cone depositor, computes the deposit bound: MARS of `terrain` at the smallest construction kappa of slots
/// 1..starts.size() (throws InvalidArgument when MARS cannot be computed for it).
WorldState world_state_at(const scenario::Scenario& scenario, Heightmap terrain, const std::vector<Position>& starts);

/// Height of the cell under (x, y) [m], or NaN when off the grid.
double height_under(const Heightmap& terrain, double x_m, double y_m);

}  // namespace marsala::world_server
