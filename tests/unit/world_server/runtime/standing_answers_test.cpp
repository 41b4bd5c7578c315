// Standing answers against docs/runtime.md#standing-answers: an empty answer that says it stands answers every later
// frame that tells its agent nothing new, renewed for that frame's step; any news (terrain, a scan, its own pose,
// material or last result, a neighbour that moved, came or went, the run's end) ends it, as does a frame written; an
// answer that asks for something never stands; a scenario that forbids standing answers gets a frame every step.

#include "marsala/world_server/runtime/standing_answers.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

namespace marsala::world_server {
namespace {

protocol::SensorFrame frame(std::uint64_t step) {
  protocol::SensorFrame f;
  f.agent_id = 2;
  f.step = step;
  f.x_m = 1.05;
  f.y_m = 2.05;
  f.z_m = 0.3;
  f.material_m3 = 0.5;
  f.last_result = protocol::ActionResult::kAccepted;
  Neighbour n;
  n.agent_id = 3;
  n.position = {2.0, 2.0};
  n.radius_m = 0.5;
  f.neighbours.push_back(n);
  return f;
}

protocol::ActionRequest answer(std::uint64_t step, bool standing = true) {
  protocol::ActionRequest r;
  r.agent_id = 2;
  r.session = 9;
  r.step = step;
  r.state = "idle";
  r.waiting_for = "nothing";
  r.decision_us = 40;
  r.decision_cpu_us = 30;
  r.standing = standing;
  return r;
}

TEST(StandingAnswers, AnEmptyAnswerThatSaysItStandsAnswersFramesWithNothingNewForTheirStep) {
  StandingAnswers answers(3, true);
  const protocol::SensorFrame told = frame(4);
  ASSERT_TRUE(answers.answered(2, answer(4)));
  for (std::uint64_t step : {5u, 6u, 500u}) {
    const std::optional<protocol::ActionRequest> r = answers.stands_for(2, frame(step), &told);
    ASSERT_TRUE(r) << step;
    EXPECT_EQ(r->step, step);
    EXPECT_EQ(r->state, "idle");
    EXPECT_EQ(r->waiting_for, "nothing");
    EXPECT_EQ(r->session, 9u);
    EXPECT_TRUE(r->standing);
    EXPECT_EQ(r->decision_us, 0u) << "no decision was made for a held step";
    EXPECT_EQ(r->decision_cpu_us, 0u);
  }
  EXPECT_FALSE(answers.stands_for(1, frame(5), &told)) << "another agent holds no answer";
  EXPECT_FALSE(answers.stands_for(7, frame(5), &told)) << "no such slot";
}

TEST(StandingAnswers, AnyNewsInTheFrameEndsIt) {
  const std::vector<std::pair<std::string, std::function<void(protocol::SensorFrame&)>>> news{
      {"a tile", [](protocol::SensorFrame& f) { f.tiles.emplace_back(); }},
      {"a scan without hits", [](protocol::SensorFrame& f) { f.scanned = true; }},
      {"scan points", [](protocol::SensorFrame& f) { f.points.push_back({0.1f, 0.2f, 0.3f}); }},
      {"the run's end", [](protocol::SensorFrame& f) { f.run_over = true; }},
      {"its x", [](protocol::SensorFrame& f) { f.x_m += 1e-12; }},
      {"its y", [](protocol::SensorFrame& f) { f.y_m -= 0.1; }},
      {"the ground under it", [](protocol::SensorFrame& f) { f.z_m += 0.001; }},
      {"its material", [](protocol::SensorFrame& f) { f.material_m3 = 0.25; }},
      {"its last result", [](protocol::SensorFrame& f) { f.last_result = protocol::ActionResult::kRejected; }},
      {"the reason", [](protocol::SensorFrame& f) { f.last_reason = "not occupiable"; }},
      {"a neighbour moved", [](protocol::SensorFrame& f) { f.neighbours[0].position.x += 0.05; }},
      {"a neighbour's ground", [](protocol::SensorFrame& f) { f.neighbours[0].z_m = 0.02; }},
      {"another neighbour", [](protocol::SensorFrame& f) { f.neighbours[0].agent_id = 4; }},
      {"a neighbour came", [](protocol::SensorFrame& f) { f.neighbours.push_back(f.neighbours[0]); }},
      {"the neighbour went", [](protocol::SensorFrame& f) { f.neighbours.clear(); }},
  };
  const protocol::SensorFrame told = frame(4);
  for (const auto& [what, change] : news) {
    StandingAnswers answers(3, true);
    ASSERT_TRUE(answers.answered(2, answer(4)));
    protocol::SensorFrame next = frame(5);
    change(next);
    EXPECT_FALSE(answers.stands_for(2, next, &told)) << what;
  }
}

TEST(StandingAnswers, AFrameWrittenEndsItAndTheNextAnswerDecides) {
  StandingAnswers answers(3, true);
  const protocol::SensorFrame first = frame(4);
  ASSERT_TRUE(answers.answered(2, answer(4)));
  protocol::SensorFrame moved = frame(5);
  moved.x_m = 1.15;
  EXPECT_TRUE(answers.end(2)) << "the moved frame is written: the answer stood until then";
  EXPECT_FALSE(answers.stands_for(2, moved, &moved)) << "told, then not answered yet";
  EXPECT_FALSE(answers.end(2)) << "nothing stands any more";
  ASSERT_TRUE(answers.answered(2, answer(5, false)));
  EXPECT_FALSE(answers.stands_for(2, moved, &moved)) << "an answer for its step only";
  ASSERT_TRUE(answers.answered(2, answer(5)));
  protocol::SensorFrame later = moved;
  later.step = 6;
  EXPECT_TRUE(answers.stands_for(2, later, &moved)) << "compared with the frame told last";
  EXPECT_FALSE(answers.stands_for(2, later, &first)) << "not with an earlier one";
  EXPECT_FALSE(answers.stands_for(2, frame(6), &moved));
  answers.end(2);
  EXPECT_FALSE(answers.stands_for(2, later, &moved));
}

TEST(StandingAnswers, AnAnswerThatAsksForSomethingNeverStands) {
  const std::vector<std::pair<std::string, std::function<void(protocol::ActionRequest&)>>> asks{
      {"a motion", [](protocol::ActionRequest& r) { r.move = true; }},
      {"a deposition", [](protocol::ActionRequest& r) { r.depositions.push_back({1, 2, 0.01}); }},
      {"a deposit", [](protocol::ActionRequest& r) { r.deposits.push_back({{1.0, 2.0}, 0.001}); }},
      {"a refill", [](protocol::ActionRequest& r) { r.refill = true; }},
  };
  const protocol::SensorFrame told = frame(4);
  for (const auto& [what, change] : asks) {
    StandingAnswers answers(3, true);
    protocol::ActionRequest r = answer(4);
    change(r);
    EXPECT_FALSE(answers.answered(2, r)) << what;
    EXPECT_FALSE(answers.stands_for(2, frame(5), &told)) << what;
  }
  StandingAnswers untold(3, true);
  ASSERT_TRUE(untold.answered(2, answer(4)));
  EXPECT_FALSE(untold.stands_for(2, frame(5), nullptr)) << "no frame written to the agent yet";
}

TEST(StandingAnswers, AScenarioWithoutStandingAnswersGetsAFrameEveryStep) {
  StandingAnswers answers(3, false);
  const protocol::SensorFrame told = frame(4);
  EXPECT_TRUE(answers.answered(2, answer(4))) << "not a fault of the agent's";
  EXPECT_FALSE(answers.stands_for(2, frame(5), &told));
  EXPECT_FALSE(answers.end(2)) << "nothing stood";
}

}  // namespace
}  // namespace marsala::world_server
