#include "marsala/world_server/runtime/request_selection.hpp"

#include <gtest/gtest.h>

namespace marsala::world_server {
namespace {

TEST(RequestSelection, TakesEightOtherRequestsPerPartitionAndCountsTheRestAsSurplus) {
  RequestSelection selection(2);
  int taken = 0;
  for (int k = 0; k < 20; ++k) taken += selection.take(1, false) == RequestTake::kOther ? 1 : 0;
  EXPECT_EQ(taken, 8);
  EXPECT_EQ(selection.surplus(), 12u);
  // The other partition has a limit of its own.
  EXPECT_EQ(selection.take(2, false), RequestTake::kOther);
}

TEST(RequestSelection, TheOwnersAnswerIsAlwaysTakenEvenAfterAFlood) {
  RequestSelection selection(2);
  for (int k = 0; k < 100; ++k) selection.take(2, false);
  EXPECT_FALSE(selection.answered(2));
  EXPECT_EQ(selection.take(2, true), RequestTake::kAnswer);
  EXPECT_TRUE(selection.answered(2));
  // A second answer is a duplicate: it counts against the limit like any other request (here: beyond it).
  EXPECT_EQ(selection.take(2, true), RequestTake::kSurplus);
  EXPECT_EQ(selection.surplus(), 93u);
}

TEST(RequestSelection, AStepIsAnsweredWhenEveryLiveAgentHasAnswered) {
  RequestSelection selection(3);
  EXPECT_TRUE(selection.all_answered({}));
  selection.take(1, true);
  selection.take(3, false);
  EXPECT_FALSE(selection.all_answered({1, 3}));
  EXPECT_TRUE(selection.all_answered({1}));
  selection.take(3, true);
  EXPECT_TRUE(selection.all_answered({1, 3}));
  EXPECT_FALSE(selection.all_answered({1, 2, 3}));
}

}  // namespace
}  // namespace marsala::world_server
