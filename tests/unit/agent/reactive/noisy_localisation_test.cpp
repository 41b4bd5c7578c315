// A robot with localisation error: it acts on a believed pose, its requests are carried out from its true one. The
// reference is the plain behaviour driven by hand with the believed frame.

#include "marsala/agent/reactive/noisy_localisation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "marsala/agent/executive/pose_error.hpp"
#include "marsala/agent/reactive/ramp_builder.hpp"
#include "marsala/core/random.hpp"
#include "unit/agent/agent_test_support.hpp"

namespace marsala::agent::reactive {
namespace {

AgentContext noisy_context(double sd) {
  AgentContext c = test::agent_context(2, test::husky());
  c.type.behaviour = "ramp_builder";
  c.type.localisation.noise_sd_m = sd;
  c.type.localisation.correlation_steps = 30.0;
  c.seed = 11;
  return c;
}

TEST(NoisyLocalisation, OnlyARobotTypeWithNoiseIsWrapped) {
  EXPECT_NE(dynamic_cast<RampBuilder*>(make_robot_behaviour(noisy_context(0.0)).get()), nullptr);
  const auto noisy = make_robot_behaviour(noisy_context(0.1));
  ASSERT_NE(dynamic_cast<NoisyLocalisation*>(noisy.get()), nullptr);
  EXPECT_EQ(noisy->name(), "ramp_builder");
  EXPECT_THROW(make_robot_behaviour([] {
                 AgentContext c = noisy_context(0.1);
                 c.type.localisation.correlation_steps = 0.0;
                 return c;
               }()),
               InvalidArgument);
}

TEST(NoisyLocalisation, ActsOnTheBelievedPoseAndShiftsItsRequestsBack) {
  const Heightmap world = test::platform_world();
  const AgentContext context = noisy_context(0.15);
  NoisyLocalisation noisy(context, "ramp_builder");
  const protocol::Admission admission = test::admission_on(context, world.geometry(), {8.5, 3.0}, {0.55, 3.05});
  noisy.on_admission(admission);

  // The reference: the same behaviour fed the believed frames by hand.
  RampBuilder plain(context);
  plain.on_admission(admission);
  executive::PoseError error(context.type.localisation, random::derive_seed(context.seed, context.agent_id));

  Position truth{5.0, 3.0};
  int moves = 0, deposits = 0, offsets = 0;
  for (std::uint64_t step = 0; step < 60; ++step) {
    protocol::SensorFrame frame = test::full_frame(context, step, truth, 5.0, world);
    frame.neighbours.push_back(test::neighbour_at(5, 2.0, 1.0));
    const Position e = error.at(step);
    // The error in whole cells of 0.1 m: rows grow southwards.
    const CellIndex k{-static_cast<int>(std::floor(0.5 + e.y / 0.1)), static_cast<int>(std::floor(0.5 + e.x / 0.1))};
    EXPECT_EQ(registration_offset(e, 0.1), k);
    offsets += k != CellIndex{0, 0};
    const Position shift{k.col * 0.1, -k.row * 0.1};
    protocol::SensorFrame believed = frame;
    believed.x_m += shift.x;
    believed.y_m += shift.y;
    believed.neighbours[0].position.x += shift.x;
    believed.neighbours[0].position.y += shift.y;
    plain.set_registration(k);
    const protocol::ActionRequest expected = plain.decide(believed);
    const protocol::ActionRequest got = noisy.decide(frame);
    EXPECT_EQ(noisy.last_error().x, e.x);
    EXPECT_EQ(noisy.last_offset(), k);
    EXPECT_EQ(got.move, expected.move) << step;
    if (got.move) {
      ++moves;
      // The robot drives the displacement it meant, from where it truly is.
      EXPECT_NEAR(got.target_x_m - truth.x, expected.target_x_m - believed.x_m, 1e-12);
      EXPECT_NEAR(got.target_y_m - truth.y, expected.target_y_m - believed.y_m, 1e-12);
      truth = {got.target_x_m, got.target_y_m};
    }
    // Every deposition lands k cells back: on the world cell the robot saw in its believed cell.
    ASSERT_EQ(got.depositions.size(), expected.depositions.size()) << step;
    for (std::size_t i = 0; i < got.depositions.size(); ++i) {
      ++deposits;
      EXPECT_EQ(got.depositions[i].row, expected.depositions[i].row - k.row);
      EXPECT_EQ(got.depositions[i].col, expected.depositions[i].col - k.col);
      EXPECT_EQ(got.depositions[i].height_m, expected.depositions[i].height_m);
      // Where it lands relative to the true pose is where it was planned relative to the believed one: within
      // reach and off the body, as the world requires.
      const Position landed = world.cell_center({got.depositions[i].row, got.depositions[i].col});
      const double d = std::hypot(landed.x - truth.x, landed.y - truth.y);
      EXPECT_LE(d, context.type.body.reach_m + 1e-9);
      EXPECT_GT(d, 0.5 * context.type.body.navigability.delta_m);
    }
    EXPECT_EQ(got.state, expected.state);
  }
  EXPECT_GT(moves, 5);      // the robot drove towards the platform
  EXPECT_GT(deposits, 10);  // and built
  EXPECT_GT(offsets, 10);   // with an error of at least a cell most of the time
}

TEST(NoisyLocalisation, RegistrationOffsetRoundsTheErrorToWholeCells) {
  EXPECT_EQ(registration_offset({0.0, 0.0}, 0.25), (CellIndex{0, 0}));
  EXPECT_EQ(registration_offset({0.12, -0.12}, 0.25), (CellIndex{0, 0}));
  EXPECT_EQ(registration_offset({0.13, 0.13}, 0.25), (CellIndex{-1, 1}));  // believed north-east: row up, col right
  EXPECT_EQ(registration_offset({-0.4, -0.6}, 0.25), (CellIndex{2, -2}));
}

}  // namespace
}  // namespace marsala::agent::reactive
