#include "marsala/protocol/end_reason.hpp"

#include "marsala/core/enum_names.hpp"

namespace marsala::protocol {
namespace {

constexpr EnumName<EndReason> kEndReasonNames[] = {{EndReason::kSignal, "signal"},
                                                   {EndReason::kCompleted, "completed"},
                                                   {EndReason::kMaxSteps, "max_steps"},
                                                   {EndReason::kNoLiveAgents, "no_live_agents"},
                                                   {EndReason::kStalled, "stalled"}};

}  // namespace

int exit_code(EndReason reason) {
  switch (reason) {
    case EndReason::kCompleted: return 0;
    case EndReason::kMaxSteps: return 3;
    case EndReason::kNoLiveAgents: return 4;
    case EndReason::kSignal: return 5;
    case EndReason::kStalled: return 6;
  }
  return 1;
}

int exit_code(EndReason reason, std::uint32_t slots_missing) {
  return reason == EndReason::kCompleted && slots_missing > 0 ? kExitCompletedShort : exit_code(reason);
}

std::string to_string(EndReason reason) { return enum_to_string(kEndReasonNames, reason); }

EndReason end_reason_from_string(const std::string& name) {
  return enum_from_string(kEndReasonNames, name, "end reason");
}

std::optional<EndReason> find_end_reason(const std::string& name) {
  for (const EnumName<EndReason>& n : kEndReasonNames)
    if (name == n.name) return n.value;
  return std::nullopt;
}

}  // namespace marsala::protocol
