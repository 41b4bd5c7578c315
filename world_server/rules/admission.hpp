#pragma once
// Admission of agents (docs/runtime.md#admission): pure decisions on hellos, and the Admission
// message that answers each one.

#include <cstdint>
#include <string>

#include "marsala/protocol/messages.hpp"
#include "marsala/world_server/rules/world_state.hpp"

namespace marsala::world_server {

/// How often a dropped agent may take its slot back in one run (docs/runtime.md#re-admission).
inline constexpr std::uint32_t kMaxReadmissions = 3;

/// What an accepted hello does.
enum class AdmissionKind {
  kRefused,      ///< nothing: the hello is refused
  kFirst,        ///< admits the slot for the first time (before the run starts)
  kRepeat,       ///< the admitted session says hello again: nothing changes
  kReadmission,  ///< a dropped agent takes its slot back (any session), with the state the world kept
  kTakeover,     ///< a new session takes a live slot whose session is no longer connected (a restarted process)
};

/// The world's answer to one hello.
struct AdmissionDecision {
  bool accepted = false;
  std::string reason;  ///< why not, when refused
  AdmissionKind kind = AdmissionKind::kRefused;
  std::uint32_t agent_id = 0;  ///< the slot it admits: the hello's, or the one assigned to an "any slot" hello
};

/// The agent id of a hello that asks for any free slot of its robot type (marsala-agent --id auto).
inline constexpr std::uint32_t kAnySlot = 0;

/// Decides on `hello` (docs/runtime.md#refusal-reasons): refused for an unknown id (no slot in this run), a body with
/// non-finite or absurd values, a body that differs from the slot's robot type, an agent dropped kMaxReadmissions
/// times already, an id admitted with another session that is still connected (`holder_connected`: the slot's
/// request writer is alive), or (when `run_started`) an agent not admitted before the start. A dropped agent is
/// re-admitted; a live slot whose session is no longer connected is taken over by the new session.
/// A hello with agent_id kAnySlot (docs/runtime.md#any-slot) gets the slot its session already holds (kRepeat), else
/// before the start the lowest never-admitted slot whose robot type has the hello's body and behaviour (kFirst),
/// else a refusal; decision.agent_id names the slot.
AdmissionDecision decide_admission(const WorldState& state, const protocol::AgentHello& hello, bool run_started,
                                   bool holder_connected = true);

/// Carries out an accepted decision. kFirst: session, name, alive, pose at its start with the height under it,
/// material at capacity. kReadmission and kTakeover: alive again under the hello's session and name, pose and
/// material as the world kept them, miss counts cleared, readmissions + 1 (kReadmission). kRepeat: nothing.
/// Returns true when the slot's session changed or it became live (its endpoints must be opened).
bool admit(WorldState& state, const protocol::AgentHello& hello, AdmissionKind kind = AdmissionKind::kFirst);

/// The hello as the slot `decision` admits it: agent_id = decision.agent_id; an "any slot" hello (kAnySlot) is
/// also named `<robot type>-<id>`, the name a fixed-id agent of that slot gives, so run.log, events and statuses
/// tell auto-assigned agents apart.
protocol::AgentHello slot_hello(const WorldState& state, const protocol::AgentHello& hello,
                                const AdmissionDecision& decision);

/// The Admission message for `hello` and `decision`; geometry, start, target and base are filled for known ids.
protocol::Admission admission_message(const WorldState& state, const protocol::AgentHello& hello,
                                      const AdmissionDecision& decision, const std::string& run_id);

}  // namespace marsala::world_server
