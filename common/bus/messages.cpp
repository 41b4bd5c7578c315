#include "common/bus/messages.hpp"

#include "common/error.hpp"

namespace marsala::bus {

std::string partition_for(const std::string& run_id, std::uint32_t agent_id) {
  return run_id + "/agent-" + std::to_string(agent_id);
}

std::string to_string(ActionResult r) {
  switch (r) {
    case ActionResult::kNone: return "none";
    case ActionResult::kAccepted: return "accepted";
    case ActionResult::kRejected: return "rejected";
    case ActionResult::kMissed: return "missed";
  }
  return "unknown";
}

namespace {
constexpr EventKind kEventKinds[] = {EventKind::kAdmitted, EventKind::kRefused, EventKind::kRejected,
                                     EventKind::kDeposited, EventKind::kMissed,  EventKind::kDropped,
                                     EventKind::kAtGoal,   EventKind::kRunOver};
}  // namespace

std::string to_string(EventKind k) {
  switch (k) {
    case EventKind::kAdmitted: return "admitted";
    case EventKind::kRefused: return "refused";
    case EventKind::kRejected: return "rejected";
    case EventKind::kDeposited: return "deposited";
    case EventKind::kMissed: return "missed";
    case EventKind::kDropped: return "dropped";
    case EventKind::kAtGoal: return "at_goal";
    case EventKind::kRunOver: return "run_over";
  }
  return "unknown";
}

EventKind event_kind_from_string(const std::string& name) {
  std::string valid;
  for (EventKind k : kEventKinds) {
    if (to_string(k) == name) return k;
    valid += (valid.empty() ? "" : ", ") + to_string(k);
  }
  throw InvalidArgument("unknown event kind '" + name + "'; valid: " + valid);
}

}  // namespace marsala::bus
