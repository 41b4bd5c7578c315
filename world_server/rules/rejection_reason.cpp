#include "marsala/world_server/rules/rejection_reason.hpp"

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala::world_server {
namespace {

constexpr std::array<const char*, kRejectionReasons> kNames = {"identity",   "future_step", "duplicate", "envelope",
                                                               "motion",     "deposition",  "refill"};

}  // namespace

std::string to_string(RejectionReason reason) { return kNames.at(static_cast<std::size_t>(reason)); }

RejectionReason rejection_reason_from_string(const std::string& name) {
  for (std::size_t i = 0; i < kRejectionReasons; ++i)
    if (name == kNames[i]) return static_cast<RejectionReason>(i);
  throw InvalidArgument(fmt::format("unknown rejection reason '{}' (valid: {}, {}, {}, {}, {}, {}, {})", name,
                                    kNames[0], kNames[1], kNames[2], kNames[3], kNames[4], kNames[5], kNames[6]));
}

RejectionReason rejection_reason_of_rule(int rule) {
  switch (rule) {
    case 1: return RejectionReason::kEnvelope;
    case 2: return RejectionReason::kMotion;
    case 3: return RejectionReason::kDeposition;
    case 4: return RejectionReason::kRefill;
    default: throw InvalidArgument(fmt::format("validation rule {} does not exist (1-4)", rule));
  }
}

}  // namespace marsala::world_server
