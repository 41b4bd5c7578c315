#pragma once
// Why the world rejected a request, in a few words fit for a metric's label (docs/runtime.md#metrics): the cases of
// apply_step (docs/runtime.md#duplicates-and-stale-steps) and the validation rules 1-4 (docs/runtime.md#validation).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace marsala::world_server {

/// The kind of a rejection; every rejected request has exactly one.
enum class RejectionReason : std::uint8_t {
  kIdentity,    ///< "identity": not the admitted identity of the partition's agent (forged or misdirected)
  kFutureStep,  ///< "future_step": a request for a step after the current one
  kDuplicate,   ///< "duplicate": a second, different request for the step
  kEnvelope,    ///< "envelope": rule 1
  kMotion,      ///< "motion": rule 2 (collisions included)
  kDeposition,  ///< "deposition": rule 3 (depositions and deposits)
  kRefill,      ///< "refill": rule 4
};

/// How many reasons there are [count].
inline constexpr std::size_t kRejectionReasons = 7;

/// Rejections of each reason, indexed by the reason's value [count].
using RejectionCounts = std::array<std::uint32_t, kRejectionReasons>;

/// "identity", "future_step", "duplicate", "envelope", "motion", "deposition", "refill".
std::string to_string(RejectionReason reason);
/// The reason named `name`; throws InvalidArgument listing the valid names.
RejectionReason rejection_reason_from_string(const std::string& name);
/// The reason of validation rule `rule` (1-4, Verdict::rule); throws InvalidArgument for any other number.
RejectionReason rejection_reason_of_rule(int rule);

}  // namespace marsala::world_server
