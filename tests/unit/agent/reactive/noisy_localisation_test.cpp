// A robot with localisation error: it acts on a believed pose, its requests are carried out from its true one. The
// reference is the plain behaviour driven by hand with the believed frame.

#include "marsala/agent/reactive/noisy_localisation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/agent/executive/pose_error.hpp"
#include "marsala/agent/reactive/ramp_builder.hpp"
#include "marsala/core/random.hpp"
#include "marsala/core/ray_caster.hpp"
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

// A scanning robot's error acts on its hits continuously (docs/runtime.md#localisation-error): it believes it stands
// at true + e and inserts the offsets it measured from its true pose from there, so every hit lands displaced by e,
// not by the whole cells of its registration. The reference is a map built by hand from that definition (the error
// drawn here, the sensor origin at true + e); a map whose scan went in at the whole-cell pose differs from it.
TEST(NoisyLocalisation, AScanningRobotsHitsLandDisplacedByItsWholeError) {
  Heightmap rough({80, 120, 0.0, 0.0, 0.1}, 0.0);
  for (int r = 0; r < rough.rows(); ++r)
    for (int c = 0; c < rough.cols(); ++c) rough(r, c) = 0.3 * std::sin(0.21 * c) + 0.2 * std::cos(0.17 * r);
  int differ_from_cells = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    AgentContext context = noisy_context(0.05);
    context.seed = seed;
    context.type.sensor = sensor_defaults(SensorKind::kLaser);
    NoisyLocalisation noisy(context, "ramp_builder");
    noisy.on_admission(test::admission_on(context, rough.geometry(), {10.0, 4.0}, {1.0, 4.0}));

    const Position truth{6.05, 4.05};
    protocol::SensorFrame frame;
    frame.agent_id = context.agent_id;
    frame.x_m = truth.x;
    frame.y_m = truth.y;
    frame.z_m = rough(*rough.cell_at(truth));
    frame.material_m3 = 1.0;
    frame.scanned = true;
    frame.points = cast_scan(rough, sensor_origin(rough, truth.x, truth.y, context.type.sensor), 0.0,
                             context.type.sensor, scan_seed(1, context.agent_id, 0));
    noisy.decide(frame);

    const Position e =
        executive::PoseError(context.type.localisation, random::derive_seed(seed, context.agent_id)).at(0);
    const CellIndex k{-static_cast<int>(std::floor(0.5 + e.y / 0.1)), static_cast<int>(std::floor(0.5 + e.x / 0.1))};
    const Position believed{truth.x + 0.1 * k.col, truth.y - 0.1 * k.row};
    const double mount = context.type.sensor.mount_height_m;
    const auto by_hand = [&](Position sensor_xy) {
      executive::MappingSystem map(rough.geometry(), 16, context.type.sensor);
      map.set_registration(k);
      map.integrate({}, believed);
      map.integrate_scan(frame.points, {sensor_xy.x, sensor_xy.y, frame.z_m + mount});
      map.assume_ground(believed, frame.z_m,
                        0.5 * context.type.body.navigability.delta_m + context.type.body.max_step_m);
      return map;
    };
    const executive::MappingSystem whole = by_hand({truth.x + e.x, truth.y + e.y});
    const executive::MappingSystem cells = by_hand(believed);
    const deliberative::KnownMap got = *noisy.known_map();
    ASSERT_GT(whole.known_cells(), 500) << seed;
    EXPECT_TRUE(got.known == whole.known()) << "seed " << seed;
    EXPECT_TRUE(got.heights.heights() == whole.heights().heights()) << "seed " << seed;
    differ_from_cells += !(got.heights.heights() == cells.heights().heights()) || !(got.known == cells.known());
  }
  EXPECT_EQ(differ_from_cells, 6);  // no error drawn is a whole number of cells
}

}  // namespace
}  // namespace marsala::agent::reactive
