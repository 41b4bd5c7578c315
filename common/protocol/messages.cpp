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

namespace {

template <typename Enum, std::size_t N>
Enum from_wire(const EnumName<Enum> (&names)[N], std::uint8_t value, const char* type) {
  for (const EnumName<Enum>& n : names)
    if (static_cast<std::uint8_t>(n.value) == value) return n.value;
  throw InvalidArgument("malformed sample: " + std::to_string(value) + " is not an " + type + " (valid 0.." +
                        std::to_string(N - 1) + ")");
}

}  // namespace

ActionResult action_result_from_wire(std::uint8_t value) {
  return from_wire(kActionResultNames, value, "ActionResult");
}

EventKind event_kind_from_wire(std::uint8_t value) { return from_wire(kEventKindNames, value, "EventKind"); }

}  // namespace marsala::protocol
