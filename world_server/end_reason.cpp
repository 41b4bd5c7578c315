#include "marsala/world_server/end_reason.hpp"

#include "marsala/core/enum_names.hpp"

namespace marsala::world_server {
namespace {

constexpr EnumName<EndReason> kEndReasonNames[] = {{EndReason::kSignal, "signal"},
                                                   {EndReason::kCompleted, "completed"},
                                                   {EndReason::kMaxSteps, "max_steps"},
                                                   {EndReason::kNoLiveAgents, "no_live_agents"}};

}  // namespace

int exit_code(EndReason reason) {
  switch (reason) {
    case EndReason::kCompleted: return 0;
    case EndReason::kMaxSteps: return 3;
    case EndReason::kNoLiveAgents: return 4;
    case EndReason::kSignal: return 5;
  }
  return 1;
}

std::string to_string(EndReason reason) { return enum_to_string(kEndReasonNames, reason); }

EndReason end_reason_from_string(const std::string& name) {
  return enum_from_string(kEndReasonNames, name, "end reason");
}

}  // namespace marsala::world_server
