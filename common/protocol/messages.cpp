#include "marsala/protocol/messages.hpp"

#include <cstring>

#include "marsala/core/enum_names.hpp"
#include "marsala/core/format.hpp"

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

std::string partition_for(const std::string& run_id, std::uint32_t agent_id, std::uint64_t session) {
  return fmt::format("{}/agent-{}-{:016x}", run_id, agent_id, session);
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_request(const ActionRequest& a, const ActionRequest& b) {
  // Bitwise on the doubles, so that a repeated request is recognised even when it carries a NaN.
  if (a.agent_id != b.agent_id || a.session != b.session || a.step != b.step || a.move != b.move ||
      !same_bits(a.target_x_m, b.target_x_m) || !same_bits(a.target_y_m, b.target_y_m) || a.refill != b.refill ||
      a.state != b.state || a.waiting_for != b.waiting_for || a.standing != b.standing ||
      a.depositions.size() != b.depositions.size() || a.deposits.size() != b.deposits.size())
    return false;
  for (std::size_t i = 0; i < a.deposits.size(); ++i) {
    const Deposit &p = a.deposits[i], &q = b.deposits[i];
    if (!same_bits(p.centre.x, q.centre.x) || !same_bits(p.centre.y, q.centre.y) ||
        !same_bits(p.volume_m3, q.volume_m3))
      return false;
  }
  for (std::size_t i = 0; i < a.depositions.size(); ++i) {
    const Deposition &p = a.depositions[i], &q = b.depositions[i];
    if (p.row != q.row || p.col != q.col || !same_bits(p.height_m, q.height_m)) return false;
  }
  return true;
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
  throw InvalidArgument(fmt::format("malformed sample: {} is not an {} (valid 0..{})", value, type, N - 1));
}

}  // namespace

ActionResult action_result_from_wire(std::uint8_t value) {
  return from_wire(kActionResultNames, value, "ActionResult");
}

EventKind event_kind_from_wire(std::uint8_t value) { return from_wire(kEventKindNames, value, "EventKind"); }

}  // namespace marsala::protocol
