#pragma once
// The ramp builder's steps (paper §IV, Fig. 2), shared by the "ramp_builder" and "path_builder" behaviours: each
// behaviour keeps its own state machine and calls these steps with the deliberative and executive modules of paper
// Fig. 1 that RampSteps owns.
//
// Each frame a behaviour first calls look(): the mapping system takes the frame's tiles, the goal synthesizer gives
// the target and the local map synthesizer builds the augmented local map, from which the cells too near another
// robot's body are taken out (executive/body_clearance.hpp): every route and motion then keeps clear of the
// neighbours the frame shows. Depositions are judged on the terrain alone (the masks before the neighbours were
// taken out: what stays occupiable and connected does not depend on where the others stand this step), and never
// on the base station's pad. A motion the world refused is left out of the local map (executive/refused_cells.hpp):
// a cell refused as not occupiable until the robot's map around it changes, one refused for a neighbour's body for
// kRefusedMotionSteps; a deposition cell the world refused is no deposition target for as long. Then, by its state,
// one of:
//   build_step()   plan a deposition path to the local goal (once per frame); a motion along it is possible -> move
//                  and deposit ahead (kAdvance); blocked, but depositions within reach -> deposit in place (kBuild);
//                  blocked and nothing to deposit (the gap left is under the robot) -> retreat_step() (kRetreat)
//   retreat_step() depositions within reach -> deposit in place (kRetreat); after depositing (or after many idle
//                  retreat moves) and a motion along the path is possible -> move and deposit ahead (kAdvance); else
//                  step back the way the robot came and fill what comes into reach (kRetreat)
//   return_step()  retrace the way to the base through navigable cells, in its lane (set_lane); at the base: refill
//                  (true)
// Building thus runs from the top of the ramp down to its toe (the robot backs off to fill where it stood), then the
// robot climbs, filling ahead of itself. The steps fill the request and the trace; which state follows is the
// behaviour's.

#include <cstdint>
#include <memory>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "marsala/agent/agent_context.hpp"
#include "marsala/agent/deliberative/goal_synthesizer.hpp"
#include "marsala/agent/deliberative/local_map_synthesizer.hpp"
#include "marsala/agent/executive/action_manager.hpp"
#include "marsala/agent/executive/body_clearance.hpp"
#include "marsala/agent/executive/deposition_manager.hpp"
#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/agent/executive/raised_cells.hpp"
#include "marsala/agent/executive/refused_cells.hpp"
#include "marsala/agent/reactive/right_of_way.hpp"
#include "marsala/core/navigable_path_planner.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::agent::reactive {

/// The base station's pad, where nothing is built, is the inner part of its refill radius: this fraction of it. The
/// middle of the base stays as it was (a payload's start, refills); the outer ring may be built on when the
/// construction begins there.
inline constexpr double kPadFraction = 0.5;
/// A robot that maps with range scans leaves this many noise spreads of a cell's height (scan_gap_margin_m()) of each
/// cell's MARS gap unfilled (DepositionParams::gap_margin_m).
inline constexpr double kScanGapMargin = 3.0;
/// How far a scanned map may read a cell `distance_m` [m] away (horizontally) off its height [m]: kScanGapMargin
/// spreads of the height a hit gives. A hit's range error moves it along its ray: up or down by the ray's vertical
/// part (the sensor at its mount height over flat ground), and along the ground by the horizontal part, which on a
/// surface of slope `kappa` [m/m] (the steepest the robot builds) is a height error of kappa times as much. 0 for a
/// noise-free sensor. Throws InvalidArgument on a negative or non-finite distance or kappa.
double scan_gap_margin_m(const SensorSpec& sensor, double distance_m, double kappa);
/// The noise margin of the robot's sure way out on a scanned map (executive::DepositionParams::exit_margin_m): this
/// many noise spreads at a body length [count].
inline constexpr double kScanExitMargin = 2.0;
/// A scanning robot deposits only on cells one of its last kFreshScans scans hit: an older reading may be from before
/// another robot built there, and filling that stale gap again overbuilds [scans].
inline constexpr int kFreshScans = 3;
/// ... and only on a gap (beyond its margin) that its last kConfirmScans scans all showed: a single scan misreads a
/// surface by a step's height now and then (hits near a riser), and a gap filled on such a reading is a bump others
/// build around [scans].
inline constexpr int kConfirmScans = 3;
/// A motion target or deposition cell the world refused for a reason other than the terrain (a neighbour's body) is
/// left out of the robot's local map for this many steps [steps].
inline constexpr std::uint64_t kRefusedMotionSteps = 40;

/// What the building steps did: the robot moved along the path, deposited in place, or is backing off.
enum class BuildPhase : std::uint8_t { kAdvance = 0, kBuild = 1, kRetreat = 2 };
/// "advance", "build", "retreat".
std::string to_string(BuildPhase phase);

/// What the steps of one frame saw and chose (for tests, logs and measurements). Reset it at the start of every
/// frame: it also holds the frame's deposition path, planned at most once per frame.
struct BuildTrace {
  CellIndex window_offset;                  ///< world index of the local map's top-left cell
  CellIndex local_goal;                     ///< local index
  std::optional<CellIndex> local_origin;    ///< local index
  long long navigable_cells = 0;            ///< cells navigable from the robot in the local map [count]
  bool planned = false;                     ///< a path was planned this frame (plan holds it)
  PlannerResult plan;                       ///< path in local indices
  std::optional<executive::Motion> motion;  ///< local indices
  executive::DepositionPlan deposition;
  bool refill = false;
  bool home_route = false;  ///< return_step() headed along the trip's way home over the robot's map (home_goal)
};

/// What the robot sees in one frame: the augmented local map around it and its target.
struct BuildView {
  deliberative::LocalMap local;
  Position robot;   ///< the frame's position [m]
  Position target;  ///< the goal synthesizer's target, or the robot's position when nothing is left to build [m]
};

/// The modules of one building robot and the steps that use them; see the header.
class RampSteps {
 public:
  /// Throws InvalidArgument for an unknown goal synthesizer, an invalid body or construction. `planner` defaults to
  /// default_planner_params for the construction width.
  explicit RampSteps(const AgentContext& context, std::optional<PlannerParams> planner = std::nullopt);
  ~RampSteps();

  /// The agent's context (with its admission once admitted).
  const AgentContext& context() const { return context_; }
  /// Checks the admission against the context and makes the modules for its grid; throws InvalidArgument when the
  /// admission is for another agent or session, or its grid is invalid.
  void admit(const protocol::Admission& admission);
  /// True once admitted.
  bool admitted() const { return modules_ != nullptr; }
  /// The agent's own map; throws InvalidArgument before admission.
  const executive::MappingSystem& map() const;
  /// The motion targets the world refused that the robot holds out (world indices as its map registers them);
  /// throws InvalidArgument before admission.
  const executive::RefusedCells& refused() const;
  /// Where the terrain of the next frames is registered (executive::MappingSystem::set_registration); kept across
  /// admissions.
  void set_registration(CellIndex offset);
  /// The localisation error the registration leaves out [m]: scans are inserted from the frame's position plus this
  /// (Behaviour::set_sub_cell_error); kept across admissions.
  void set_sub_cell_error(Position error_m) { sub_cell_error_ = error_m; }

  /// Integrates the frame into the map, asks the goal synthesizer for the target and synthesizes the local map;
  /// records the window in `trace`. Only after admission.
  BuildView look(const protocol::SensorFrame& frame, BuildTrace& trace);

  /// Plans the deposition path from the robot to the local goal into trace.plan, unless this frame planned one;
  /// true when one was found.
  bool plan_path(const deliberative::LocalMap& local, BuildTrace& trace);
  /// Plans the deposition path from the robot to the cell of `towards` [m] (priced as plan_path() prices it) into
  /// trace.plan, instead of to the local goal; to the local goal when `towards` lies outside the window or is not
  /// passable. True when one was found.
  bool plan_path_towards(const deliberative::LocalMap& local, Position towards, BuildTrace& trace);
  /// The action manager's motion along `path` (local indices) from `robot` [m], or nullopt when no progress is
  /// possible.
  std::optional<executive::Motion> advance(const deliberative::LocalMap& local, const std::vector<CellIndex>& path,
                                           Position robot) const;
  /// Lanes for routes (executive/lane.hpp): offset_m to the right of a corridor's centre line, corridors up to
  /// corridor_width_m [m] each side of the path; offset 0 (the default): no lanes.
  void set_lane(double offset_m, double corridor_width_m);
  /// One construction band for every front robot (docs/runtime.md#the-construction-band): when on, what the robot
  /// fills follows its deposition path moved onto the centre line of the corridor it runs in (executive/lane.hpp
  /// band_centre_path, on its own map without the other robots), not the path from where it stands; it still drives
  /// its own path; nothing along a stretch of it that runs beside the structure (the cells its map saw raised,
  /// executive/raised_cells.hpp); and what is left to fill is the MARS gap of the way's own surface, the cells the
  /// body drives on along that path (executive::way_fill_gap: the terrain beside it raises nothing in it). Needs set_lane()'s corridor width; off by default; set before
  /// admit().
  void set_band_centre(bool on) { band_centre_ = on; }
  /// Under the rays (docs/runtime.md#mapping): when on, a scanning robot's map records the latest scan's rays over the
  /// cells within its reach, a body and a step (executive::MappingSystem::record_overflights), and the unknown cells
  /// under them are work up to the MARS height of the known cells (LocalMapSynthesizer::fill_under_rays), current for
  /// as long as a scan keeps passing over them. Off by default; set before admit().
  void set_fill_under_rays(bool on) { fill_under_rays_ = on; }
  /// `path` moved into this robot's lane on the last look()'s map (unchanged without lanes).
  std::vector<CellIndex> in_lane(const deliberative::LocalMap& local, const std::vector<CellIndex>& path) const;
  /// Requests `motion` and records it.
  void move(const executive::Motion& motion, BuildTrace& trace, protocol::ActionRequest& request);
  /// A step back the way the robot came: towards the local origin, or the oldest navigable cell of the trajectory in
  /// the window when the robot stands on the origin, or (it has not moved yet) to the navigable cell farthest from
  /// the local goal; when another robot cuts the way there, towards the navigable cell farthest from the local goal;
  /// nullopt when there is none or no route to it.
  std::optional<executive::Motion> step_back(const deliberative::LocalMap& local, Position robot) const;
  /// A scanning robot whose map leaves it no move (its own cell the only navigable one) asks the world the way it came:
  /// a motion to the last cell it stood on other than its own, when that lies within a step and the world has not
  /// refused it since (docs/runtime.md#a-sure-way-out). Its map of the cells around it reads within noise; the world
  /// judges on the truth, and a refusal names the drop with its heights. nullopt otherwise.
  std::optional<executive::Motion> retrace(const deliberative::LocalMap& local, Position robot) const;

  /// A scanning robot blocked on its path with nothing to fill asks the world the path's next cell: a motion to it when
  /// its map holds the cell out for the terrain alone (a ball it cannot judge, a pit it never saw, a step read within
  /// noise too high), the cell lies within a step and clear of the neighbours, and the world has not refused it on the
  /// map as it reads now, and no drop the world named in its ball still lies below its level
  /// (docs/runtime.md#refused-requests). The world judges on the truth: it accepts, or its
  /// refusal names the drop with its heights, which the map keeps (MappingSystem::record_drop) and the robot fills.
  /// nullopt otherwise.
  std::optional<executive::Motion> ask_ahead(const deliberative::LocalMap& local, const std::vector<CellIndex>& path,
                                             Position robot) const;

  /// A scanning robot walled in on its map (walled_in(), asked first), or whose map leaves it no way back (step_back()
  /// and retrace() found none), asks the world the way it came: along a route over its known cells to the latest
  /// cell of its trajectory a body length away and no nearer its goal, the route's next cell (advance(), or
  /// ask_ahead() when the map holds it out). The route runs around the cells the world has answered already (refused,
  /// or failing a drop it named: hold_out_told_drops()), which it would refuse again. A walled-in robot keeps that
  /// cell while it stays walled in (`walled`: walled_in(), as the caller found it; Memory::ask_back_anchor). nullopt
  /// otherwise.
  std::optional<executive::Motion> ask_back(const deliberative::LocalMap& local, Position robot, bool walled);
  /// A scanning robot on an island of its map: no navigable cell lies a body length away. Always false for a robot
  /// that reads exact heights.
  bool walled_in(const deliberative::LocalMap& local, Position robot) const;

  /// A step away from a robot at `from` [m] (giving way, reactive/right_of_way.hpp): towards the navigable cell within
  /// two body lengths farthest from it, when that is farther than the robot stands; nullopt when there is none.
  std::optional<executive::Motion> step_away(const deliberative::LocalMap& local, Position robot, Position from) const;

  /// Keeps out of the lanes of robots with the right of way (right_of_way.hpp): their cells leave `local`'s
  /// occupiable and navigable cells (not the robot's own). True when the robot stands in one of them.
  static bool keep_out_of(deliberative::LocalMap& local, Position robot, const std::vector<Lane>& lanes);
  /// A step out of the lanes: towards the navigable cell outside them nearest the robot (route length); nullopt when
  /// there is none in the window.
  std::optional<executive::Motion> leave_lanes(const deliberative::LocalMap& local, Position robot,
                                               const std::vector<Lane>& lanes) const;

  /// One frame of the right of way (right_of_way.hpp) for a robot at `robot` [m] that keeps it: `local` loses the lanes
  /// of the robots with the right of way (keep_out_of); then, in this order, a step out of such a lane, a step away
  /// from the robot it gives way to, nothing more when `at_goal` (the behaviour's own), standing aside or holding
  /// (nothing requested). Returns what the robot waits for ("right of way: ...", then "; robots <close_by> close by"
  /// unless empty) when the protocol took the frame; nullopt when the behaviour's own step goes on.
  /// Without `lanes` no lane is kept (a pipeline's robots all drive one corridor, in lanes of their own).
  std::optional<std::string> right_of_way_step(const RightOfWay& protocol, deliberative::LocalMap& local,
                                               Position robot, bool at_goal, const std::string& close_by,
                                               BuildTrace& trace, protocol::ActionRequest& request,
                                               bool lanes = true);

  /// Advance, build or start retreating (see the header); nullopt, with nothing requested, when no deposition path
  /// leads through known cells (the behaviour's state stays: wait for the map to grow).
  std::optional<BuildPhase> build_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame,
                                       BuildTrace& trace, protocol::ActionRequest& request);
  /// One step of a retreat (see the header): kRetreat, or kAdvance once the robot moves up the path again.
  BuildPhase retreat_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, BuildTrace& trace,
                          protocol::ActionRequest& request);
  /// One step towards the base station through navigable cells; true when the request refills (the robot is within
  /// the base radius now or after this motion).
  bool return_step(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, BuildTrace& trace,
                   protocol::ActionRequest& request);

 private:
  struct Modules;
  /// How many scans in a row showed a cell's gap (count_gap_scans).
  struct GapStreak {
    int last_scan = 0;  ///< the map's scan that last showed the gap
    int scans = 0;      ///< scans in a row, up to that one, that showed it
  };
  /// What the request being built sends (the last move()'s and deposit()'s): for the map once the world accepts it
  /// (MappingSystem::record_built), for the deposit limit and the refused cells when it refuses it.
  struct Sent {
    std::optional<CellIndex> motion;  ///< the world cell the request moves to (as the map registers it)
    std::vector<Deposition> layers;
    std::vector<Deposit> deposits;
  };
  /// A drop the world named (rule 2.3), for its lower cell: the height it is filled to, and the height below which
  /// the pair still breaks the body's rule (the fill less its rounding) [m], against `high` (world index), the higher
  /// cell of the pair that asks the most.
  struct DropLevel {
    double fill_m = 0.0;
    double pass_m = 0.0;
    CellIndex high;
  };
  /// What the steps remember from one frame to the next.
  // plan_gap(), band_gap(): the last window's sources (the first-seen heights, the way's heights) and their MARS
  // bound at the construction kappa.
  struct PlanBound {
    CellIndex offset{-1, -1};
    Heightmap first;
    CellMask wanted;  // the cells bound holds the MARS bound on (h elsewhere)
    Heightmap bound;
  };
  // The MARS bound of `sources` (window at `offset`) at the construction kappa on the cells gap_below() reads for
  // `local` (executive::gap_cells()), from `memo` when its sources are these, bit for bit, and it holds those cells.
  const Heightmap& bound_of(PlanBound& memo, const deliberative::LocalMap& local, Heightmap sources) const;
  struct Memory {
    Sent sent;
    /// The world gives deposits (cube, cone) their shape and may judge one the prediction passed: after a rejected
    /// request with deposits, the next ones carry at most half as many (none after one), until one is accepted, so a
    /// mismatch never repeats the same request forever. -1: no limit.
    int deposit_limit = -1;
    std::optional<executive::RefusedCells> refused;              ///< motion targets the world refused
    std::optional<executive::RefusedCells> refused_depositions;  ///< deposition cells the world refused
    /// The last frame's refusal, recorded once this frame's scan is in the map: the cell, whether for the terrain
    /// (else for now) and whether a motion (else a deposition).
    struct Refusal {
      CellIndex cell;
      bool terrain = false;
      bool motion = false;
      std::vector<executive::DropRefusal> drops;  ///< the drops the world named, the worst first
    };
    std::optional<Refusal> refusal;
    std::vector<GapStreak> gap_streaks;            ///< scanned maps, per world cell (row-major): count_gap_scans()
    /// Scanned maps, per world cell (row-major): the map's scan count when a neighbour last stood within reach of it
    /// (mark_others_near()); 0: never.
    std::vector<int> others_near;
    bool deposited_since_blocked = false;          ///< the retreat deposited since the path was last blocked
    int idle_retreat_moves = 0;                    ///< retreat moves without work since
    /// Where a walled-in robot asks its way back to (ask_back(), world index): kept while it stays walled in, so that
    /// a step within its island does not turn it to another cell of its trajectory.
    std::optional<CellIndex> ask_back_anchor;
    std::vector<executive::BodyClearance> others;  ///< the last frame's neighbours
    CellMask corridor;                             ///< the last local map's navigable cells, neighbours not taken out
    CellMask terrain_occupiable;                   ///< and its occupiable cells
    std::vector<CellIndex> home;                   ///< the way home of this trip (world cells), empty: not planned
    double return_nearest_m = std::numeric_limits<double>::infinity();  ///< this trip's nearest to the base [m]
    int return_no_nearer = 0;  ///< return steps since the robot last got nearer the base than return_nearest_m
    PlanBound plan_bound;  ///< plan_gap()'s memo
    PlanBound band_bound;  ///< band_gap()'s memo
    std::optional<executive::RaisedCells> raised;  ///< set_band_centre(): the structure seen built (first heights)
    Position target;                               ///< this frame's target (synthesize_view()) [m]
    /// Scanned maps: per drop's lower cell (world index), the levels of the pairs the world named there
    /// (record_drop_level()).
    std::map<CellIndex, DropLevel> drop_levels;
  };

  // look()'s steps, in order.
  void remember_result(const protocol::SensorFrame& frame);              // what the world made of the last request
  void update_map(const protocol::SensorFrame& frame);                   // tiles, scan and the ground under the body
  // A drop the world named: the level its lower cell must reach for the pair to pass (Memory::drop_levels).
  void record_drop_level(const executive::DropRefusal& drop);
  // Scanned maps: the gap of each told drop's lower cell in the window is at least what its level asks (less nothing
  // for noise: the heights were told).
  void fill_to_drop_levels(deliberative::LocalMap& local) const;
  // A told drop with both its cells in the body ball of `cell` (local index) still lies below its DropLevel::pass_m:
  // the world would refuse the cell again.
  bool fails_a_told_drop(const deliberative::LocalMap& local, CellIndex cell) const;
  // The window's cells (local indices) for which fails_a_told_drop() holds, set to 0 in `mask`.
  void hold_out_told_drops(const deliberative::LocalMap& local, CellMask& mask) const;
  void learn_refusals(const protocol::SensorFrame& frame);               // the world's refusals on the new map
  BuildView synthesize_view(const protocol::SensorFrame& frame);         // target, local map, the gap to work on
  void keep_clear(const protocol::SensorFrame& frame, BuildView& view);  // the neighbours and the refused cells
  void deposit(const deliberative::LocalMap& local, const protocol::SensorFrame& frame, Position at, std::size_t from,
               BuildTrace& trace, protocol::ActionRequest& request);
  // set_band_centre(): `ahead` (local indices, from where the robot will stand) on the corridor's centre line.
  std::vector<CellIndex> on_band_centre(const deliberative::LocalMap& local, const std::vector<CellIndex>& ahead) const;
  // set_band_centre(): the window's gap against the way's surface along `ahead` alone (executive::way_fill_gap).
  Heightmap band_gap(const deliberative::LocalMap& local, const std::vector<CellIndex>& ahead);
  // band_gap(): the half-width of the way whose surface is the fill's only source [m].
  double way_radius_m() const;
  // set_band_centre(): the price the planner routes by: the window's gap against the terrain as first seen
  // (executive::first_seen_gap), so what is built raises no price beside it, and 0 on the cells built (built_cells).
  Heightmap plan_gap(const deliberative::LocalMap& local);
  // Plans the deposition path from the robot to local cell `goal` (priced as plan_path() prices it) into trace.plan.
  void plan_to(const deliberative::LocalMap& local, CellIndex goal, BuildTrace& trace);
  // set_band_centre(): the window's cells seen raised since first seen (RaisedCells::raised), the structure.
  CellMask built_cells(const deliberative::LocalMap& local) const;
  std::optional<CellIndex> oldest_navigable_trajectory_cell(const deliberative::LocalMap& local) const;
  void clear_pad_gap(deliberative::LocalMap& local) const;  // no work on the base station's pad
  /// A scanned map: counts, per cell of the window, the scans in a row that showed its gap (beyond the margin) on a
  /// surface a recent scan hit (kFreshScans, kConfirmScans).
  void count_gap_scans(const deliberative::LocalMap& local, bool scanned);
  /// A scanned map: marks the cells within a step and a reach of each neighbour the frame shows (where it may build).
  void mark_others_near(const protocol::SensorFrame& frame);
  /// A scanned map: true when what the map says of `cell` (world index) is current: one of the last kFreshScans scans
  /// hit it, or a scan hit it and no neighbour came within reach of it since (only this robot built there, and its
  /// own construction is in its map).
  bool current(CellIndex cell) const;
  /// A scanned map: no work where the gap is not confirmed: on a cell no recent scan hit (others may have built there
  /// since) or whose gap fewer than kConfirmScans scans in a row showed (one scan's misread surface is no gap). The
  /// path is still planned on the whole gap.
  void clear_unconfirmed_gap(deliberative::LocalMap& local) const;
  /// At the base: the refill asked for; the trip's way home and return progress forgotten.
  void refilled(BuildTrace& trace, protocol::ActionRequest& request);
  /// On the way back: the cell of the way home (deliberative/home_route.hpp, planned when the trip has none or the
  /// robot left it) farthest along it that the robot can reach in its window; nullopt when bodies cut it there.
  std::optional<CellIndex> home_goal(const deliberative::LocalMap& local);
  static std::optional<CellIndex> farthest_navigable_from_goal(const deliberative::LocalMap& local);

  AgentContext context_;
  std::optional<PlannerParams> planner_;
  std::unique_ptr<deliberative::GoalSynthesizer> goal_;
  std::unique_ptr<Modules> modules_;  // made on admission, when the grid is known
  CellIndex registration_{0, 0};      // set_registration()
  Position sub_cell_error_{0.0, 0.0};  // set_sub_cell_error() [m]
  double lane_offset_m_ = 0.0;        // set_lane()
  double corridor_width_m_ = 0.0;
  bool band_centre_ = false;  // set_band_centre()
  bool fill_under_rays_ = false;  // set_fill_under_rays()
  Memory memory_;
};

}  // namespace marsala::agent::reactive
