#pragma once
// Admission of agents (docs/runtime.md#admission): pure decisions on hellos, and the Admission
// message that answers each one.

#include <string>

#include "marsala/protocol/messages.hpp"
#include "marsala/world_server/world_state.hpp"

namespace marsala::world_server {

/// The world's answer to one hello.
struct AdmissionDecision {
  bool accepted = false;
  std::string reason;  ///< why not, when refused
};

/// Decides on `hello`: refused for an unknown id (no slot in this run), a body with non-finite or absurd values, a
/// body that differs from the slot's robot type, an agent already dropped, an id admitted with another session, or
/// (when `run_started`) an agent not admitted before the start. A repeated hello of an admitted session is accepted
/// again.
AdmissionDecision decide_admission(const WorldState& state, const protocol::AgentHello& hello, bool run_started);

/// Admits the hello's agent (decide_admission accepted it): session, name, alive, pose at its start with the height
/// under it, material at capacity. A repeated hello of the admitted session changes nothing. Returns true when the
/// agent was newly admitted.
bool admit(WorldState& state, const protocol::AgentHello& hello);

/// The Admission message for `hello` and `decision`; geometry, start, target and base are filled for known ids.
protocol::Admission admission_message(const WorldState& state, const protocol::AgentHello& hello,
                                      const AdmissionDecision& decision, const std::string& run_id);

}  // namespace marsala::world_server
