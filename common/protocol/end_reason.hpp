#pragma once
// Why a run ended (docs/runtime.md#end-reasons): the world decides it, run.log and summary.json name it, the monitor
// reads it back.

#include <cstdint>
#include <optional>
#include <string>

namespace marsala::protocol {

/// Why the lockstep stopped; the first that holds at the top of a step wins, in this order.
enum class EndReason {
  kSignal,        ///< "signal": SIGINT or SIGTERM (an interrupted step is not applied)
  kCompleted,     ///< "completed": the scenario's completion holds
  kMaxSteps,      ///< "max_steps": the step limit was reached
  kNoLiveAgents,  ///< "no_live_agents": every admitted agent was dropped
  kStalled,       ///< "stalled": neither progress nor terrain changed for the scenario's stall_steps steps
};

/// marsala-world's exit code for a run that ended for `reason` and wrote its outputs (docs/runtime.md#exit-codes):
/// 0 completed, 3 max_steps, 4 no_live_agents, 5 signal, 6 stalled. 1 (an error) and 2 (usage, or a run refused at
/// start) are not end reasons.
int exit_code(EndReason reason);

/// marsala-world's exit code when a run that completed was short of slots (docs/runtime.md#exit-codes): 7.
inline constexpr int kExitCompletedShort = 7;

/// marsala-world's exit code for a run that ended for `reason` with `slots_missing` slots of its team not in it at
/// the end (never admitted, or dropped and not back) [count]: exit_code(reason), except kExitCompletedShort for a
/// completed run short of any slot, so that a script sees the team did not complete it whole.
int exit_code(EndReason reason, std::uint32_t slots_missing);

/// "signal", "completed", "max_steps", "no_live_agents", "stalled".
std::string to_string(EndReason reason);
/// The reason named `name`; throws InvalidArgument listing the valid names.
EndReason end_reason_from_string(const std::string& name);
/// The reason named `name`, or none for a name that is not one (a reader of run files that may be damaged).
std::optional<EndReason> find_end_reason(const std::string& name);

}  // namespace marsala::protocol
