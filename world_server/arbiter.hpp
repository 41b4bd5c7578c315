#pragma once
// The arbiter: validates one ActionRequest against the world state exactly as docs/runtime.md#validation says (rules
// 1-4, all-or-nothing) and applies accepted ones. Pure functions of their arguments.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"
#include "marsala/protocol/messages.hpp"
#include "marsala/world_server/world_state.hpp"

namespace marsala::world_server {

/// Tolerances of docs/runtime.md#tolerances.
namespace arbiter_tolerance {
inline constexpr double kLengthM = 1e-9;        ///< added to length limits [m]
inline constexpr double kVolumeM3 = 1e-12;      ///< added to volume limits [m^3]
inline constexpr double kCubeMultiple = 1e-6;   ///< |h/q - round(h/q)| limit for a whole number of cube layers
inline constexpr double kMaxDepositionM = 1.0;  ///< tallest single deposition [m]
inline constexpr std::size_t kMaxDeposits = 256;  ///< most deposits in one request
}  // namespace arbiter_tolerance

/// How cell_occupiable decides; every method gives the same answer (ARCHITECTURE.md definition).
enum class OccupancyMethod {
  kAutomatic,  ///< pairs for balls up to a few thousand cells, the processor window beyond
  kPairs,      ///< every pair of the ball, with the processor's threshold expression
  kWindow,     ///< NavigabilityProcessor on the window that holds the ball
};

/// True when on-grid `cell` is occupiable for `params` on `terrain`: every pair of cells within delta/2 of its centre
/// (cells off the grid ignored) has |h(r) - h(q)| <= eps + kappa |r - q| + 1e-9 m. Throws InvalidArgument when the
/// cell is off the grid.
bool cell_occupiable(const Heightmap& terrain, CellIndex cell, const NavigabilityParams& params,
                     OccupancyMethod method = OccupancyMethod::kAutomatic);

/// The arbiter's answer to one request.
struct Verdict {
  bool accepted = false;
  std::string reason;      ///< why not, when rejected
  int rule = 0;            ///< the rule (1-4 of docs/runtime.md#validation) that rejected it; 0 when accepted
  double volume_m3 = 0.0;  ///< material the depositions place, when accepted [m^3]
  /// The cells the request's deposits (cube or cone depositor) raise and by how much, in the order they are
  /// applied; empty for a layer depositor's depositions, which say their cells themselves.
  std::vector<Deposition> rises;
};

/// Validates `request`, which arrived on the partition of agent `channel_id`, against `state`
/// (docs/runtime.md#validation, rules 1-4: envelope, motion, depositions after the motion, refill). Duplicates and
/// requests for other steps are apply_step's business; here a step other than state.step is a rejection.
Verdict validate_request(const WorldState& state, std::uint32_t channel_id, const protocol::ActionRequest& request);

/// Applies a request validate_request accepted: position = target, depositions or the verdict's rises (each raised
/// cell's depositor becomes the request's agent), material, refill, counts. Appends the changed cells to
/// `changed_cells`.
void apply_request(WorldState& state, const protocol::ActionRequest& request, const Verdict& verdict,
                   std::vector<CellIndex>& changed_cells);

/// Distance below which the bodies of `a` and `b` overlap: (delta_a + delta_b) / 2 [m] (docs/runtime.md#collisions).
double body_clearance_m(const AgentRecord& a, const AgentRecord& b);
/// True when the bodies of `a` at (ax, ay) and `b` at (bx, by) overlap: closer than body_clearance_m - 1e-9 m.
bool bodies_overlap(const AgentRecord& a, double ax, double ay, const AgentRecord& b, double bx, double by);

/// Thickness of one layer of cubes on a cell: cube_size^3 / cell_size^2 [m].
double cube_layer_m(double cube_size_m, double cell_size_m);

/// The cells an accepted request raised and by how much: its depositions, or its verdict's rises.
const std::vector<Deposition>& raised_cells(const protocol::ActionRequest& request, const Verdict& verdict);

}  // namespace marsala::world_server
