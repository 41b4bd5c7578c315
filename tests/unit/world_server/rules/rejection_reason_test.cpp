#include "marsala/world_server/rules/rejection_reason.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numeric>

#include "marsala/core/error.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

using testing::admitted_state;
using testing::flat_terrain;
using testing::kLayer;
using testing::move_to;
using testing::request_for;
using testing::small_scenario;

std::uint32_t of(const StepOutcome& o, RejectionReason reason) {
  return o.rejected_by_reason[static_cast<std::size_t>(reason)];
}

std::uint32_t total(const StepOutcome& o) {
  return std::accumulate(o.rejected_by_reason.begin(), o.rejected_by_reason.end(), 0u);
}

TEST(RejectionReason, NamesReadBack) {
  const char* names[] = {"identity", "future_step", "duplicate", "envelope", "motion", "deposition", "refill"};
  for (std::size_t i = 0; i < kRejectionReasons; ++i) {
    EXPECT_EQ(to_string(static_cast<RejectionReason>(i)), names[i]);
    EXPECT_EQ(rejection_reason_from_string(names[i]), static_cast<RejectionReason>(i));
  }
  EXPECT_THROW(rejection_reason_from_string("rule 2"), InvalidArgument);
}

TEST(RejectionReason, OfEachValidationRule) {
  EXPECT_EQ(rejection_reason_of_rule(1), RejectionReason::kEnvelope);
  EXPECT_EQ(rejection_reason_of_rule(2), RejectionReason::kMotion);
  EXPECT_EQ(rejection_reason_of_rule(3), RejectionReason::kDeposition);
  EXPECT_EQ(rejection_reason_of_rule(4), RejectionReason::kRefill);
  EXPECT_THROW(rejection_reason_of_rule(0), InvalidArgument);
  EXPECT_THROW(rejection_reason_of_rule(5), InvalidArgument);
}

// Each kind of rejection apply_step makes lands under its own reason, and the reasons add up to the step's count.
TEST(RejectionReason, ApplyStepCountsEachRejectionUnderItsReason) {
  WorldState w = admitted_state(small_scenario(), flat_terrain(), 2);

  protocol::ActionRequest future = request_for(w, 2);
  future.step = w.step + 1;
  protocol::ActionRequest forged = request_for(w, 1);
  forged.session += 7;  // no admitted identity
  StepOutcome o = apply_step(w, std::vector<Submission>{{1, forged},
                                                        {1, move_to(w, 1, 1.25, 1.05)},
                                                        {1, move_to(w, 1, 0.85, 1.05)},  // a second, different one
                                                        {2, future}});
  EXPECT_EQ(of(o, RejectionReason::kIdentity), 1u);
  EXPECT_EQ(of(o, RejectionReason::kDuplicate), 1u);
  EXPECT_EQ(of(o, RejectionReason::kFutureStep), 1u);
  EXPECT_EQ(total(o), 3u);
  EXPECT_EQ(o.rejected, 3u);

  // Rule 1: a target that is not a number; rule 2: a move of 2 m, beyond the test robot's step.
  protocol::ActionRequest nowhere = move_to(w, 1, std::numeric_limits<double>::quiet_NaN(), 1.05);
  o = apply_step(w, std::vector<protocol::ActionRequest>{nowhere, move_to(w, 2, w.agent(2).position.x + 2.0,
                                                                          w.agent(2).position.y)});
  EXPECT_EQ(of(o, RejectionReason::kEnvelope), 1u);
  EXPECT_EQ(of(o, RejectionReason::kMotion), 1u);
  EXPECT_EQ(total(o), 2u);
  EXPECT_EQ(w.rejected_motions, 1u);

  // Rule 3: a deposition 1.5 m away, out of reach.
  protocol::ActionRequest far = request_for(w, 1);
  far.depositions.push_back({40 - 1 - 25, 12, kLayer});
  o = apply_step(w, std::vector<protocol::ActionRequest>{far, request_for(w, 2)});
  EXPECT_EQ(of(o, RejectionReason::kDeposition), 1u);
  EXPECT_EQ(total(o), 1u);
  EXPECT_EQ(o.rejected, 1u);
}

}  // namespace
}  // namespace marsala::world_server
