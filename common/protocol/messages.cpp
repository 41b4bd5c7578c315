#include "marsala/protocol/messages.hpp"

#include "marsala/core/enum_names.hpp"

namespace marsala::protocol {
namespace {

constexpr EnumName<ActionResult> kActionResultNames[] = {{ActionResult::kNone, "none"},
                                                         {ActionResult::kAccepted, "accepted"},
                                                         {ActionResult::kRejected, "rejected"},
                                                         {ActionResult::kMissed, "missed"}};

constexpr EnumName<EventKind> kEventKindNames[] = {
    {EventKind::kAdmitted, "admitted"},   {EventKind::kRefused, "refused"}, {EventKind::kRejected, "rejected"},
    {EventKind::kDeposited, "deposited"}, {EventKind::kMissed, "missed"},   {EventKind::kDropped, "dropped"},
    {EventKind::kAtGoal, "at_goal"},      {EventKind::kRunOver, "run_over"}};

}  // namespace

std::string partition_for(const std::string& run_id, std::uint32_t agent_id) {
  return run_id + "/agent-" + std::to_string(agent_id);
}

std::string to_string(ActionResult r) { return enum_to_string(kActionResultNames, r); }
std::string to_string(EventKind k) { return enum_to_string(kEventKindNames, k); }
EventKind event_kind_from_string(const std::string& name) {
  return enum_from_string(kEventKindNames, name, "event kind");
}

}  // namespace marsala::protocol
