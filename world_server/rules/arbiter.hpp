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
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// Limits of docs/runtime.md#validation (the tolerances are the core's, marsala::tolerance).
inline constexpr double kMaxDepositionM = 1.0;     ///< tallest single deposition [m]
inline constexpr std::size_t kMaxDeposits = 256;   ///< most deposits in one request
inline constexpr std::size_t kMaxNamedDrops = 32;  ///< most drops a terrain refusal names (rules 2.3, 2.4)

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

/// The cells an accepted request raised and by how much: its depositions, or its verdict's rises.
const std::vector<Deposition>& raised_cells(const protocol::ActionRequest& request, const Verdict& verdict);

}  // namespace marsala::world_server
