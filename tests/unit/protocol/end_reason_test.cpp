#include "marsala/protocol/end_reason.hpp"

#include <gtest/gtest.h>

#include "marsala/core/error.hpp"

namespace marsala::protocol {
namespace {

TEST(EndReason, NamesAreTheDocumentedStringsAndReadBack) {
  const std::pair<EndReason, const char*> names[] = {{EndReason::kSignal, "signal"},
                                                     {EndReason::kCompleted, "completed"},
                                                     {EndReason::kMaxSteps, "max_steps"},
                                                     {EndReason::kNoLiveAgents, "no_live_agents"},
                                                     {EndReason::kStalled, "stalled"}};
  for (const auto& [reason, name] : names) {
    EXPECT_EQ(to_string(reason), name);
    EXPECT_EQ(end_reason_from_string(name), reason);
  }
}

TEST(EndReason, ExitCodesSayHowTheRunEnded) {
  EXPECT_EQ(exit_code(EndReason::kCompleted), 0);
  EXPECT_EQ(exit_code(EndReason::kMaxSteps), 3);
  EXPECT_EQ(exit_code(EndReason::kNoLiveAgents), 4);
  EXPECT_EQ(exit_code(EndReason::kSignal), 5);
  EXPECT_EQ(exit_code(EndReason::kStalled), 6);
}

TEST(EndReason, ACompletedRunShortOfSlotsHasAnExitCodeOfItsOwn) {
  EXPECT_EQ(exit_code(EndReason::kCompleted, 0), 0);
  EXPECT_EQ(exit_code(EndReason::kCompleted, 1), 7);
  EXPECT_EQ(exit_code(EndReason::kCompleted, 2), 7);
  // A run that did not complete says why, whatever slots it missed.
  EXPECT_EQ(exit_code(EndReason::kMaxSteps, 1), 3);
  EXPECT_EQ(exit_code(EndReason::kNoLiveAgents, 3), 4);
  EXPECT_EQ(exit_code(EndReason::kSignal, 1), 5);
  EXPECT_EQ(exit_code(EndReason::kStalled, 2), 6);
  // 7 is none of the end reasons' own codes.
  for (EndReason r : {EndReason::kSignal, EndReason::kCompleted, EndReason::kMaxSteps, EndReason::kNoLiveAgents,
                      EndReason::kStalled})
    EXPECT_NE(exit_code(r), kExitCompletedShort);
}

TEST(EndReason, AnUnknownNameListsTheValidOnes) {
  try {
    end_reason_from_string("finished");
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(),
                 "unknown end reason 'finished'; valid: signal, completed, max_steps, no_live_agents, stalled");
  }
  EXPECT_EQ(to_string(static_cast<EndReason>(42)), "unknown");
}

}  // namespace
}  // namespace marsala::protocol
