#include "marsala/protocol/messages.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::protocol {
namespace {

TEST(Messages, PartitionsNameTheRunAndTheAgent) { EXPECT_EQ(partition_for("ramp-d7", 12, 0x1234abcd5678ef90), "ramp-d7/agent-12-1234abcd5678ef90"); }

TEST(Messages, EnumNamesReadBack) {
  for (const EventKind k : {EventKind::kAdmitted, EventKind::kRefused, EventKind::kRejected, EventKind::kDeposited,
                            EventKind::kMissed, EventKind::kDropped, EventKind::kAtGoal, EventKind::kRunOver})
    EXPECT_EQ(event_kind_from_string(to_string(k)), k);
  EXPECT_EQ(to_string(ActionResult::kMissed), "missed");
  EXPECT_THROW(event_kind_from_string("exploded"), InvalidArgument);
}

TEST(Messages, WireOctetsDecodeOnlyToDefinedValues) {
  for (std::uint8_t v = 0; v <= 3; ++v) EXPECT_EQ(static_cast<std::uint8_t>(action_result_from_wire(v)), v);
  for (std::uint8_t v = 0; v <= 7; ++v) EXPECT_EQ(static_cast<std::uint8_t>(event_kind_from_wire(v)), v);
  try {
    action_result_from_wire(200);
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "malformed sample: 200 is not an ActionResult (valid 0..3)");
  }
  EXPECT_THROW(action_result_from_wire(4), InvalidArgument);
  EXPECT_THROW(event_kind_from_wire(8), InvalidArgument);
  EXPECT_THROW(event_kind_from_wire(255), InvalidArgument);
}

}  // namespace
}  // namespace marsala::protocol
