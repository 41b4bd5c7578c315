#pragma once
// Deposition manager (paper §III, executive layer): turns the MARS gap under a planned path's footprint into this
// step's depositions. Cells go in path order (the footprint of the path cell nearest the robot first), each raised
// towards its local MARS height P in whole cube layers q = cube^3 / cs^2, rounded down so that it never overshoots
// P (rounding to nearest would let each built cell lift the bound of the next by up to q/2, and a ramp built cell
// by cell would creep flatter and longer than kappa). Every rule the world checks is kept: reach, never under a
// robot, at most 1 m per cell, total volume within the deposition threshold and the material on board; and never on
// the base station's pad (cells whose centre lies within its radius), where robots refill and a payload starts.
// Finally
// the depositions are simulated on the local map: the robot's (new) cell must stay occupiable, connected to the
// window's border and to the local origin, and so must every neighbour in the window that was connected;
// depositions that would break that are dropped.

#include <cstdint>
#include <optional>
#include <vector>

#include "marsala/agent/deliberative/local_map_synthesizer.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// The body's limits that bound a step's depositions.
struct DepositionParams {
  NavigabilityParams navigability;    ///< the robot's kappa [m/m], delta [m], eps [m]
  double footprint_m = 1.0;           ///< diameter of the band filled around each path cell [m] (construction width)
  double reach_m = 1.2;               ///< manipulator reach from the robot's centre [m]
  double max_deposit_m3 = 0.01;       ///< deposition threshold per step [m^3]
  double cube_layer_m = 0.0125;       ///< q = cube^3 / cs^2: the height of one cube spread over a cell [m]
  double max_height_m = 1.0;          ///< largest single deposition [m]
  double neighbour_keep_out_m = 0.7;  ///< no deposition this close to a neighbour's centre [m]
  double neighbour_step_m = 0.2;      ///< how far a neighbour may move this step [m]
  Position pad_centre;                ///< the base station's pad: nothing is built on it (refills, a payload's start)
  double pad_radius_m = 0.0;          ///< its radius; 0: no pad [m]
  /// Depositions leave this much of each cell's gap unfilled: the noise of a map built from range scans, which the
  /// robot must not chase (a cell read a little low filled, a cell read a little high lifts the MARS bound of its
  /// neighbours: filled too, the bound rises again). 0 for exact maps [m].
  double gap_margin_m = 0.0;
  /// A map built from range scans: the noise of a pair of its readings [m]; 0 for exact maps. One of the robot's 8
  /// neighbour cells is a sure way out when it is occupiable with eps less this margin; without one, nothing is raised
  /// where it could close a neighbour cell (clearance_m()).
  double exit_margin_m = 0.0;
  /// A map built from range scans: a cone pile stays this far [m] below every cell it may not raise (under a robot,
  /// on the pad, unread), which the map reads within its noise; 0 for exact maps.
  double pile_margin_m = 0.0;
  /// A map built from range scans: a robot whose map gives it no way out of its window keeps every cell it can still
  /// reach on its map read within its noise and no nearer its goal, its way back (keeps_way_back()). Exact maps keep
  /// only the way out they have, as before.
  bool keep_reach_without_way_out = false;
};

/// The deposition parameters of a body on a grid of cell_size_m [m], with the team's keep-out [m]; the footprint is
/// footprint_m when given, else the body's delta.
DepositionParams deposition_params(const RobotBody& body, double cell_size_m, double neighbour_keep_out_m,
                                   std::optional<double> footprint_m = std::nullopt);

/// The robots around this one at the start of the step, as its frame reports them.
struct Neighbourhood {
  std::uint32_t self_id = 0;      ///< this robot's agent id
  Position self;                  ///< this robot's position at the start of the step [m]
  std::vector<Neighbour> others;  ///< the other robots within proximity range
};

/// One candidate deposition (local index).
struct DepositionCandidate {
  CellIndex cell;       ///< local index
  int layers = 0;       ///< whole cube layers
  double height_m = 0;  ///< layers * q [m]
};

/// A cell the plan wants raised towards its MARS height (local index).
struct WantedCell {
  CellIndex cell;     ///< local index
  double gap_m = 0;   ///< its MARS gap [m]
};

/// This step's depositions (layer depositor) or deposits (cube, cone: executive/depositor.hpp).
struct DepositionPlan {
  std::vector<Deposition> depositions;  ///< world indices, in path order
  std::vector<Deposit> deposits;        ///< positions [m] and volumes [m^3], in the order they are applied
  double volume_m3 = 0.0;               ///< sum of height * cs^2 (depositions) or of the deposits' volumes [m^3]
  /// True when the plan deposits anything.
  bool any() const { return !depositions.empty() || !deposits.empty(); }
  int candidates = 0;                   ///< candidates before the way-back check [count]
  int dropped_for_way_back = 0;         ///< candidates dropped to keep the way back [count]
};

/// The local cells the segment from the centre of local cell `from` to `to` [m] crosses, `from` first, each once, up
/// to where it leaves the window (sampled every half cell). A deposition path for candidates() along the straight way
/// to a target: where the planned path turns aside from it (docs/runtime.md#mapping), the band ahead is still work.
std::vector<CellIndex> line_cells(const deliberative::LocalMap& map, CellIndex from, Position to);

/// Chooses a step's depositions along a path.
class DepositionManager {
 public:
  /// Throws InvalidArgument on non-positive or non-finite limits.
  explicit DepositionManager(DepositionParams params);
  const DepositionParams& params() const { return params_; }

  /// The depositions the world would accept from a robot standing at `robot` [m] (after this step's motion) with
  /// `material_m3` on board, without the way-back check; budget-limited. Cells nearer than the keep-out to a
  /// neighbour are skipped, and so are cells outside this robot's territory: a cell belongs to the robot whose cell
  /// (at the start of the step) is nearest in whole cells, ties to the lower id. Robots decide on the same frame
  /// state, so two of them never fill the same cell in one step (each would fill it to the MARS height it saw).
  std::vector<DepositionCandidate> candidates(const deliberative::LocalMap& map, const std::vector<CellIndex>& path,
                                              Position robot, double material_m3,
                                              const Neighbourhood& neighbours) const;
  /// The cells along `path` (each once, in path order, the footprint of the path cell nearest the robot first) a
  /// depositor may raise, with their MARS gap > 0: known, and may_raise(). Unlike candidates(), no reach, rounding
  /// or budget: the cube and cone depositors place whole shapes (executive/depositor.hpp).
  std::vector<WantedCell> wanted(const deliberative::LocalMap& map, const std::vector<CellIndex>& path, Position robot,
                                 const Neighbourhood& neighbours) const;
  /// The same, for a caller that has the robot's clearance_m() already.
  std::vector<WantedCell> wanted(const deliberative::LocalMap& map, const std::vector<CellIndex>& path, Position robot,
                                 const Neighbourhood& neighbours, double clearance_m) const;
  /// True when local `cell` may be raised at all by a robot standing at `robot` [m]: known, farther than
  /// `clearance_m` (clearance_m()) from it, in its territory, beyond the keep-out of every neighbour, off the base
  /// station's pad.
  bool may_raise(const deliberative::LocalMap& map, CellIndex cell, Position robot, const Neighbourhood& neighbours,
                 double clearance_m) const;
  /// How near a robot standing at `robot` [m] nothing is raised [m]: under its body (delta / 2). On a scanned map
  /// (exit_margin_m > 0) without a sure way out (none of its 8 neighbour cells occupiable with eps less the margin,
  /// known and in the window), also nothing whose raise could close a neighbour cell (delta / 2 + a cell's
  /// diagonal): the way out it believes may be noise, and the one it has must not be built shut
  /// (docs/runtime.md#a-sure-way-out).
  double clearance_m(const deliberative::LocalMap& map, Position robot) const;
  /// candidates() reduced to the longest prefix that keeps the way back (keeps_way_back()).
  DepositionPlan plan(const deliberative::LocalMap& map, const std::vector<CellIndex>& path, Position robot,
                      double material_m3, const Neighbourhood& neighbours) const;
  /// True when the depositions, simulated on the local map, keep the robot's cell at `robot` [m] occupiable (if
  /// it was), keep a navigable way from it to the window's border (if it had one), and keep every robot that was
  /// connected to the local origin connected to it: this one, and each neighbour in the window wherever its own motion
  /// may take it this step (cells within neighbour_step_m). The neighbours' own depositions of the same step are
  /// unknown here: robots closer than about a body length can still wall each other in between them.
  bool keeps_way_back(const deliberative::LocalMap& map, Position robot,
                      const std::vector<DepositionCandidate>& depositions, const Neighbourhood& neighbours) const;

  /// What keeps_way_back() judges every set of depositions of one step against, built once (at the first non-empty
  /// set) and kept: the window's occupiable mask before them (blind cells never occupiable) and the reaches before
  /// them, which do not depend on the depositions tried. A search over prefixes of a deposition list asks it many
  /// times. It refers to the map and neighbourhood given to way_back(), which must outlive it.
  struct WayBack {
    const deliberative::LocalMap* map = nullptr;
    const Neighbourhood* neighbours = nullptr;
    bool ready = false;             ///< the members below are built
    std::optional<CellIndex> cell;  ///< the robot's cell, nullopt when it is outside the window
    std::vector<CellIndex> robots;  ///< this robot's cell, then each neighbour's cells within its step
    bool has_origin = false;        ///< the local origin is occupiable on the map
    CellMask before;                ///< cells navigable from the local origin before the depositions
    bool had_way_out = false;       ///< the robot's cell was occupiable and reached the window's border
    /// Without a way out: the cells navigable from the robot's cell on the heights alone, read within the map's
    /// noise (`within_noise`), and no nearer the local goal than the robot's cell, none of which the depositions may
    /// cut off; empty otherwise.
    CellMask reach;
    /// Without a way out: the occupiable cells of map.heights when a pair may break the rule by up to gap_margin_m
    /// (eps widened by it), 0 on blind cells, 1 on the robot's cell; empty otherwise.
    CellMask within_noise;
    CellMask occupiable;            ///< NavigabilityProcessor::occupiable(map.heights), 0 on blind cells
    bool occupiable_is_map = false;  ///< `occupiable` is map.occupiable, cell for cell
    Heightmap after;                ///< scratch: map.heights with the depositions tried, restored after each try
    std::vector<CellIndex> ball;    ///< the body ball's offsets (delta / 2)
    std::vector<std::uint8_t> touched;  ///< scratch: 0 per window cell between tries
  };
  WayBack way_back(const deliberative::LocalMap& map, Position robot, const Neighbourhood& neighbours) const;
  /// keeps_way_back() on the context of way_back() (the same answer).
  bool keeps_way_back(WayBack& context, const std::vector<DepositionCandidate>& depositions) const;
  /// The window's occupiable mask after `depositions` (blind cells never occupiable): the mask before them,
  /// recomputed only on the cells whose body ball holds a raised cell; equal, cell by cell, to
  /// NavigabilityProcessor::occupiable() of the raised heights with the blind cells cleared.
  CellMask occupiable_after(WayBack& context, const std::vector<DepositionCandidate>& depositions) const;

 private:
  void prepare(WayBack& context) const;
  // occupiable_after() by `rule` from its mask `before` the depositions (blind cells never occupiable); `unchanged`,
  // when given, is set to whether the mask is `before`, cell for cell.
  CellMask raised_occupiable(WayBack& context, const std::vector<DepositionCandidate>& depositions,
                             const NavigabilityProcessor& rule, const CellMask& before,
                             bool* unchanged = nullptr) const;
  bool in_territory(const deliberative::LocalMap& map, CellIndex cell, Position centre, const Neighbourhood& neighbours,
                    std::optional<CellIndex> self_cell) const;
  DepositionParams params_;
  NavigabilityProcessor navigability_;
  NavigabilityProcessor within_noise_;  ///< the rule with eps widened by gap_margin_m (WayBack::within_noise)
};

}  // namespace marsala::agent::executive
