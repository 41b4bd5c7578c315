// Fuzzes the world's request validation and step (world_server/arbiter.hpp validate_request, step.hpp apply_step):
// small seeded worlds take runs of steps of plausible requests with mutated fields (NaN, infinite and huge doubles,
// off-grid and duplicated cells, bad heights, forged ids, sessions and steps, huge lists; deposits of cube and cone
// depositors with nasty positions and volumes, of the wrong kind, many of them). Properties, checked against an
// oracle written here from docs/runtime.md rather than from arbiter.cpp: validation never throws; the terrain changes
// exactly by the accepted depositions (and the deposits' shapes, from common/core/deposit_shapes.hpp) and the
// deposited volume by their volume; heights stay finite;
// material stays within [0, capacity]; agents stay on the grid and move at most max_step_m; an accepted request
// obeys rules 1-4; rejected and unanswered agents change only their counts.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

#include "fuzz/fuzz_support.hpp"
#include "marsala/core/deposit_shapes.hpp"
#include "marsala/core/error.hpp"
#include "marsala/world_server/rules/arbiter.hpp"
#include "marsala/world_server/rules/step.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

namespace tol = tolerance;
using testing::admitted_state;
using testing::flat_terrain;
using testing::kLayer;
using testing::payload_block;
using testing::site_block;
using testing::small_scenario_text_completing;

constexpr std::uint32_t kMaxId = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t kMaxStep = std::numeric_limits<std::uint64_t>::max();

/// Builds worlds and requests from one seeded generator.
class WorldFuzzer {
 public:
  explicit WorldFuzzer(std::uint64_t seed) : mutator_(seed, {}) {}

  fuzz::Mutator& mutator() { return mutator_; }

  /// A 40 x 40 world of 0.1 m cells with 2 or 3 admitted agents, one of three completions, a bumpy or blocky
  /// terrain, agents moved anywhere on the grid, some material spent, now and then an agent dropped.
  WorldState make_world() {
    static const std::vector<std::string> kCompletions = {"goal { x0_m: 2.9 y0_m: 1.9 x1_m: 3.2 y1_m: 2.2 }",
                                                          payload_block(2), site_block(2, 0.5)};
    std::string text = small_scenario_text_completing(mutator_.pick(kCompletions));
    if (mutator_.chance(0.5)) text = with_depositors(text);
    const scenario::Scenario s = scenario::parse_scenario(text, "fuzz.pbtxt");
    Heightmap terrain = flat_terrain();
    const bool blocky = mutator_.chance(0.3);
    for (long long i = 0; i < terrain.size(); ++i)
      terrain.data()[i] = kLayer * static_cast<double>(mutator_.below(blocky ? 40 : 4));
    const std::uint32_t agents = mutator_.chance(0.5) ? 2 : 3;
    WorldState state = admitted_state(s, std::move(terrain), agents);
    // Deposits are judged against the initial terrain's MARS (rule 3d.10), which on these bumpy grids stands only
    // centimetres above the ground: in most worlds it stands 1 m higher (as a tower off the grid would lift it), so
    // that the other rules see many shapes.
    if (state.deposit_bound.size() > 0 && mutator_.chance(0.8))
      for (long long i = 0; i < state.deposit_bound.size(); ++i) state.deposit_bound.data()[i] += 1.0;
    for (AgentRecord& a : state.agents) {
      if (mutator_.chance(0.5)) {
        a.position.x = uniform(0.0, 4.0);
        a.position.y = uniform(0.0, 4.0);
        if (mutator_.chance(0.2)) a.position.x = mutator_.chance(0.5) ? 1e-9 : 4.0 - 1e-9;  // at an edge
      }
      a.z_m = height_under(state.terrain, a.position.x, a.position.y);
      a.material_m3 = mutator_.chance(0.3) ? 0.0 : uniform(0.0, a.type.body.material_capacity_m3);
    }
    if (mutator_.chance(0.1)) drop_agent(state, 1 + static_cast<std::uint32_t>(mutator_.below(agents)), "fuzz");
    if (mutator_.chance(0.1)) state.step = mutator_.chance(0.5) ? 1000 : (std::uint64_t{1} << 62);
    return state;
  }

  /// Zero or more submissions for each slot (and for no slot), most of them plausible, many mutated.
  std::vector<Submission> submissions(const WorldState& state) {
    std::vector<Submission> out;
    for (std::uint32_t id = 1; id <= state.agents.size() + 1; ++id) {
      const std::size_t count = mutator_.chance(0.15) ? 0 : mutator_.chance(0.8) ? 1 : 2 + mutator_.below(2);
      for (std::size_t k = 0; k < count; ++k) {
        Submission s;
        s.request = plausible(state, id);
        if (mutator_.chance(0.6)) mutate(state, s.request);
        s.channel_id = s.request.agent_id;
        if (mutator_.chance(0.05)) s.channel_id = pick_id(state);
        out.push_back(std::move(s));
      }
    }
    std::shuffle(out.begin(), out.end(), mutator_.rng());  // arrival order across partitions never matters
    return out;
  }

 private:
  /// The small scenario with agent 2 a cube depositor (side 0.1 m or 0.15 m) and agent 3 a cone depositor.
  std::string with_depositors(std::string text) {
    const std::string cube = mutator_.chance(0.5) ? "0.1" : "0.15";
    const std::string types = std::string(R"(
robot_type {
  name: "cuber"
  behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
  depositor { name: "cube" cube_size_m: )") + cube + R"( }
}
robot_type {
  name: "piler"
  behaviour: "scripted"
  body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2 max_deposit_m3: 0.02 material_capacity_m3: 0.05
         reach_m: 1.2 sensing_range_m: 1.0 proximity_range_m: 1.5 cube_size_m: 0.05 }
  depositor { name: "cone" repose_deg: 30 }
}
)";
    const std::size_t agents = text.find("agent {");
    text.insert(agents, types);
    const std::size_t second = text.find("robot_type: \"tester\"", text.find("agent {", agents + types.size()) + 1);
    text.replace(second, 20, "robot_type: \"cuber\"");
    const std::size_t third = text.find("robot_type: \"tester\"", second + 1);
    text.replace(third, 20, "robot_type: \"piler\"");
    return text;
  }

  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(mutator_.rng()); }

  std::uint32_t pick_id(const WorldState& state) {
    const std::uint32_t ids[] = {0, 1, 2, 3, static_cast<std::uint32_t>(state.agents.size() + 1), 99, kMaxId};
    return ids[mutator_.below(sizeof ids / sizeof ids[0])];
  }

  int pick_index(int size) {
    const int values[] = {-1,
                          size,
                          size - 1,
                          0,
                          std::numeric_limits<int>::min(),
                          std::numeric_limits<int>::max(),
                          static_cast<int>(mutator_.below(static_cast<std::size_t>(size)))};
    return values[mutator_.below(sizeof values / sizeof values[0])];
  }

  double nasty_height() {
    const double values[] = {-kLayer,
                             0.0,
                             kLayer * (1.0 + 1e-7),
                             kLayer * 0.5,
                             1.0,
                             1.0 + 1e-9,
                             1.0 + 1e-6,
                             80 * kLayer,
                             81 * kLayer,
                             1e-300,
                             mutator_.pick(fuzz::nasty_doubles())};
    return values[mutator_.below(sizeof values / sizeof values[0])];
  }

  // A request of agent `id` as a working agent would send it: a short move, a few depositions within reach.
  protocol::ActionRequest plausible(const WorldState& state, std::uint32_t id) {
    protocol::ActionRequest r;
    r.agent_id = id;
    r.step = state.step;
    if (!state.has_agent(id)) return r;
    const AgentRecord& me = state.agent(id);
    r.session = me.session;
    double x = me.position.x, y = me.position.y;
    if (mutator_.chance(0.6)) {
      const double angle = uniform(0.0, 6.283185307179586);
      const double d = uniform(0.0, 1.1 * me.type.body.max_step_m);
      r.move = true;
      r.target_x_m = x + d * std::cos(angle);
      r.target_y_m = y + d * std::sin(angle);
      x = r.target_x_m;
      y = r.target_y_m;
    }
    const auto centre = state.terrain.cell_at({x, y});
    const int reach = static_cast<int>(me.type.body.reach_m / state.terrain.cell_size_m()) + 1;
    const DepositorKind kind = me.type.depositor.kind;
    for (std::size_t n = kind == DepositorKind::kLayer ? 0 : mutator_.below(4); n > 0; --n) {
      const double angle = uniform(0.0, 6.283185307179586), d = uniform(0.0, 1.1 * me.type.body.reach_m);
      const double side = depositor_cube_size_m(me.type);
      const double volume = kind == DepositorKind::kCube ? side * side * side * static_cast<double>(1 + mutator_.below(4))
                                                         : uniform(0.0, 0.008);
      r.deposits.push_back({x + d * std::cos(angle), y + d * std::sin(angle), volume});
    }
    for (std::size_t n = kind == DepositorKind::kLayer ? mutator_.below(6) : 0; n > 0 && centre; --n) {
      const int row = centre->row + static_cast<int>(mutator_.below(2 * reach + 1)) - reach;
      const int col = centre->col + static_cast<int>(mutator_.below(2 * reach + 1)) - reach;
      r.depositions.push_back({row, col, kLayer * static_cast<double>(1 + mutator_.below(4))});
    }
    r.refill = mutator_.chance(0.1);
    r.state = "fuzzing";
    return r;
  }

  void mutate(const WorldState& state, protocol::ActionRequest& r) {
    const int rows = state.terrain.rows(), cols = state.terrain.cols();
    for (std::size_t n = 1 + mutator_.below(3); n > 0; --n) {
      switch (mutator_.below(17)) {
        case 0: r.agent_id = pick_id(state); break;
        case 1: r.session = mutator_.chance(0.5) ? r.session + 1 : mutator_.rng()(); break;
        case 2: {
          const std::uint64_t steps[] = {r.step + 1, r.step - 1, 0, kMaxStep, r.step + 1000};
          r.step = steps[mutator_.below(5)];
          break;
        }
        case 3: (mutator_.chance(0.5) ? r.target_x_m : r.target_y_m) = mutator_.pick(fuzz::nasty_doubles()); break;
        case 4: {  // just off the grid, or on its edge
          const double edges[] = {-1e-12, 0.0, 4.0, 4.0 - 1e-15, -0.05, 4.05};
          (mutator_.chance(0.5) ? r.target_x_m : r.target_y_m) = edges[mutator_.below(6)];
          r.move = true;
          break;
        }
        case 5: r.move = !r.move; break;
        case 6:
          if (!r.depositions.empty()) {
            Deposition& d = r.depositions[mutator_.below(r.depositions.size())];
            (mutator_.chance(0.5) ? d.row : d.col) = pick_index(mutator_.chance(0.5) ? rows : cols);
          }
          break;
        case 7:
          if (!r.depositions.empty()) r.depositions[mutator_.below(r.depositions.size())].height_m = nasty_height();
          break;
        case 8:
          if (!r.depositions.empty()) r.depositions.push_back(r.depositions[mutator_.below(r.depositions.size())]);
          break;
        case 9: {  // a huge list: every cell once, or more than the grid holds
          const std::size_t n_cells =
              mutator_.chance(0.5) ? static_cast<std::size_t>(rows) * cols : static_cast<std::size_t>(rows) * cols + 1;
          r.depositions.clear();
          for (std::size_t i = 0; i < n_cells; ++i)
            r.depositions.push_back({static_cast<int>(i / cols) % rows, static_cast<int>(i % cols), kLayer});
          break;
        }
        case 10: r.refill = !r.refill; break;
        case 11: r.state.assign(mutator_.chance(0.5) ? 100000 : 3, '\xff'); break;
        case 12: {  // a deposit's field nasty
          if (r.deposits.empty()) r.deposits.push_back({r.target_x_m, r.target_y_m, 0.001});
          Deposit& d = r.deposits[mutator_.below(r.deposits.size())];
          const double nasty = mutator_.chance(0.5) ? mutator_.pick(fuzz::nasty_doubles()) : nasty_height();
          (mutator_.chance(0.33) ? d.centre.x : mutator_.chance(0.5) ? d.centre.y : d.volume_m3) = nasty;
          break;
        }
        case 13:  // the other kind: a deposit from a layer robot, a deposition from a cube or cone robot
          if (mutator_.chance(0.5))
            r.deposits.push_back({r.target_x_m, r.target_y_m, 0.001});
          else
            r.depositions.push_back({20, 20, kLayer});
          break;
        case 14:  // duplicates, at the grid's edge, or many
          if (mutator_.chance(0.3)) {
            r.deposits.assign(mutator_.chance(0.5) ? 256 : 257 + mutator_.below(3000), Deposit{2.0, 2.0, 1e-6});
          } else if (!r.deposits.empty()) {
            Deposit d = r.deposits[mutator_.below(r.deposits.size())];
            if (mutator_.chance(0.5)) d.centre.x = mutator_.chance(0.5) ? 0.01 : 3.99;
            r.deposits.push_back(d);
          }
          break;
        case 15:  // volumes around the limits: a cube and a half, just over the threshold, tiny
          if (!r.deposits.empty()) {
            const double volumes[] = {0.0015, 0.001 * (1 + 1e-9), 0.02, 0.02 + 1e-9, 1e-300, 0.0, -0.001, 0.05};
            r.deposits[mutator_.below(r.deposits.size())].volume_m3 = volumes[mutator_.below(8)];
          }
          break;
        default:
          for (Deposition& d : r.depositions) d.height_m = mutator_.pick(fuzz::nasty_doubles());
          break;
      }
    }
  }

  fuzz::Mutator mutator_;
};

double distance(double ax, double ay, double bx, double by) { return std::hypot(ax - bx, ay - by); }

std::string describe(const protocol::ActionRequest& r) {
  std::ostringstream out;
  out.precision(17);
  out << "{agent " << r.agent_id << " session " << r.session << " step " << r.step << " move " << r.move << " ("
      << r.target_x_m << ", " << r.target_y_m << ") refill " << r.refill << " depositions " << r.depositions.size()
      << " deposits " << r.deposits.size();
  for (std::size_t i = 0; i < r.deposits.size() && i < 12; ++i)
    out << " {" << r.deposits[i].centre.x << "," << r.deposits[i].centre.y << " " << r.deposits[i].volume_m3 << "}";
  for (std::size_t i = 0; i < r.depositions.size() && i < 12; ++i)
    out << " [" << r.depositions[i].row << "," << r.depositions[i].col << " " << r.depositions[i].height_m << "]";
  out << "}";
  return out.str();
}

std::string describe(const WorldState& state, const std::vector<Submission>& submissions) {
  std::ostringstream out;
  out.precision(17);
  out << "step " << state.step << "; agents:";
  for (const AgentRecord& a : state.agents)
    out << " #" << a.id << (a.alive ? "" : " (not alive)") << " at (" << a.position.x << ", " << a.position.y << ") material "
        << a.material_m3 << " session " << a.session << ";";
  out << "\nsubmissions:";
  for (const Submission& s : submissions) out << "\n  on " << s.channel_id << ": " << describe(s.request);
  return out.str();
}

/// The request of `agent`'s partition that answers for it in `step` (first with its identity and this step), if any.
const protocol::ActionRequest* answer_of(const AgentRecord& agent, std::uint64_t step,
                                         const std::vector<Submission>& submissions) {
  for (const Submission& s : submissions)
    if (s.channel_id == agent.id && carries_identity_of(agent, s.request) && s.request.step == step) return &s.request;
  return nullptr;
}

/// The rejections charged to `agent` in `step` besides a rejected answer (docs/runtime.md#duplicates-and-stale-steps):
/// on its own partition, requests for future steps and duplicates that differ from its answer (an identical repeat is
/// ignored); on any live agent's partition, requests that carry `agent`'s admitted identity but not the partition
/// owner's (charged to their sender, never to the owner).
std::uint32_t extra_rejections(const WorldState& before, const AgentRecord& agent, std::uint64_t step,
                               const std::vector<Submission>& submissions) {
  std::uint32_t n = 0;
  const protocol::ActionRequest* first = nullptr;
  for (const Submission& s : submissions) {
    if (!before.has_agent(s.channel_id) || !before.agent(s.channel_id).alive) continue;
    if (!carries_identity_of(before.agent(s.channel_id), s.request)) {
      if (agent.admitted && carries_identity_of(agent, s.request)) ++n;
      continue;
    }
    if (s.channel_id != agent.id) continue;
    if (s.request.step > step) {
      ++n;
    } else if (s.request.step == step) {
      if (first && !protocol::same_request(*first, s.request)) ++n;
      if (!first) first = &s.request;
    }
  }
  return n;
}

/// Requests on live partitions that carry no admitted identity at all: counted in unattributed_rejections.
std::uint32_t unattributed(const WorldState& before, const std::vector<Submission>& submissions) {
  std::uint32_t n = 0;
  for (const Submission& s : submissions) {
    if (!before.has_agent(s.channel_id) || !before.agent(s.channel_id).alive) continue;
    if (carries_identity_of(before.agent(s.channel_id), s.request)) continue;
    const bool known = before.has_agent(s.request.agent_id) && before.agent(s.request.agent_id).admitted &&
                       before.agent(s.request.agent_id).session == s.request.session;
    n += known ? 0 : 1;
  }
  return n;
}

/// Rules 1-4 of docs/runtime.md#validation as an accepted request must satisfy them, written independently.
void check_accepted_request(const WorldState& before, const AgentRecord& me, const protocol::ActionRequest& r,
                            const std::function<std::string()>& report) {
  const RobotBody& body = me.type.body;
  ASSERT_TRUE(std::isfinite(r.target_x_m) && std::isfinite(r.target_y_m) && std::abs(r.target_x_m) < 1e6 &&
              std::abs(r.target_y_m) < 1e6)
      << report();
  double x = me.position.x, y = me.position.y;
  if (r.move) {
    ASSERT_LE(distance(r.target_x_m, r.target_y_m, x, y), body.max_step_m + tol::kLengthM) << report();
    ASSERT_TRUE(before.terrain.cell_at({r.target_x_m, r.target_y_m})) << report();
    x = r.target_x_m;
    y = r.target_y_m;
  }
  std::set<std::pair<int, int>> cells;
  double volume = 0.0;
  const double cs = before.terrain.cell_size_m();
  const double layer = cube_layer_m(body.cube_size_m, cs);
  for (const Deposition& d : r.depositions) {
    ASSERT_TRUE(before.terrain.contains({d.row, d.col})) << report();
    ASSERT_TRUE(cells.insert({d.row, d.col}).second) << "cell listed twice\n" << report();
    ASSERT_TRUE(std::isfinite(d.height_m) && d.height_m > 0.0 && d.height_m <= 1.0 + tol::kLengthM) << report();
    const double layers = d.height_m / layer;
    ASSERT_NEAR(layers, std::round(layers), tol::kCubeMultiple) << report();
    const Position c = before.terrain.cell_center({d.row, d.col});
    ASSERT_LE(distance(c.x, c.y, x, y), body.reach_m + tol::kLengthM) << report();
    volume += d.height_m * cs * cs;
  }
  const DepositorKind kind = me.type.depositor.kind;
  ASSERT_TRUE(kind == DepositorKind::kLayer ? r.deposits.empty() : r.depositions.empty())
      << "a request of the other depositor kind accepted\n"
      << report();
  ASSERT_LE(r.deposits.size(), kMaxDeposits) << report();
  for (const Deposit& d : r.deposits) {
    ASSERT_TRUE(std::isfinite(d.centre.x) && std::isfinite(d.centre.y) && std::isfinite(d.volume_m3) && d.volume_m3 > 0.0)
        << report();
    ASSERT_LE(distance(d.centre.x, d.centre.y, x, y), body.reach_m + tol::kLengthM) << report();
    if (kind == DepositorKind::kCube) {
      const double side = depositor_cube_size_m(me.type), cubes = d.volume_m3 / (side * side * side);
      ASSERT_NEAR(cubes, std::round(cubes), 1e-6) << report();
      ASSERT_GE(std::round(cubes), 1.0) << report();
    }
    volume += d.volume_m3;
  }
  ASSERT_LE(volume, body.max_deposit_m3 + tol::kVolumeM3) << report();
  ASSERT_LE(volume, me.material_m3 + tol::kVolumeM3) << report();
  if (r.refill) {
    ASSERT_LE(distance(x, y, before.base.centre.x, before.base.centre.y), before.base.radius_m + tol::kLengthM) << report();
  }
}

/// Runs one step on `state` and checks it against the oracle.
void check_step(WorldState& state, const std::vector<Submission>& submissions,
                const std::function<std::string()>& report, long long& deposit_requests) {
  // Validation alone never throws, whatever arrives on whichever partition.
  for (const Submission& s : submissions) {
    try {
      (void)validate_request(state, s.channel_id, s.request);
    } catch (const std::exception& e) {
      FAIL() << "validate_request threw " << typeid(e).name() << ": " << e.what() << " for " << describe(s.request)
             << "\n"
             << report();
    }
  }
  const WorldState before = state;
  StepOutcome outcome;
  try {
    outcome = apply_step(state, submissions);
  } catch (const std::exception& e) {
    FAIL() << "apply_step threw " << typeid(e).name() << ": " << e.what() << "\n" << report();
  }
  ASSERT_EQ(state.step, before.step + 1) << report();

  Heightmap expected = before.terrain;
  std::vector<std::uint32_t> expected_depositor(static_cast<std::size_t>(expected.size()), 0);
  double added_volume = 0.0;
  std::uint32_t accepted = 0, rejected = 0, missed = 0;
  for (std::size_t k = 0; k < before.agents.size(); ++k) {
    const AgentRecord& was = before.agents[k];
    const AgentRecord& now = state.agents[k];
    const RobotBody& body = was.type.body;
    ASSERT_TRUE(now.material_m3 >= 0.0 && now.material_m3 <= body.material_capacity_m3)
        << "agent " << was.id << " material " << now.material_m3 << "\n"
        << report();
    if (!was.alive) {
      ASSERT_EQ(now.accepted, was.accepted) << report();
      ASSERT_EQ(now.rejected - was.rejected, extra_rejections(before, was, before.step, submissions)) << report();
      rejected += now.rejected - was.rejected;
      ASSERT_TRUE(now.position.x == was.position.x && now.position.y == was.position.y && now.material_m3 == was.material_m3) << report();
      continue;
    }
    const protocol::ActionRequest* answer = answer_of(was, before.step, submissions);
    const std::uint32_t took = now.accepted - was.accepted;
    ASSERT_LE(took, 1u) << report();
    ASSERT_TRUE(took == 0 || answer) << "agent " << was.id << " accepted without an answer\n" << report();
    ASSERT_EQ(now.rejected - was.rejected,
              extra_rejections(before, was, before.step, submissions) + (answer && took == 0 ? 1 : 0))
        << "agent " << was.id << "\n"
        << report();
    ASSERT_EQ(now.missed - was.missed, answer ? 0u : 1u) << report();
    accepted += took;
    rejected += now.rejected - was.rejected;
    missed += answer ? 0 : 1;
    if (took == 0) {  // rejected or missed: nothing but counts
      ASSERT_TRUE(now.position.x == was.position.x && now.position.y == was.position.y) << "agent " << was.id << " moved\n" << report();
      ASSERT_EQ(now.material_m3, was.material_m3) << report();
      ASSERT_EQ(now.deposited_m3, was.deposited_m3) << report();
      continue;
    }
    const protocol::ActionRequest& r = *answer;
    // Rules are checked against the state this agent saw: the one the agents before it left. Only positions and
    // the terrain of other agents matter to it, and the terrain only through occupancy, which is not re-checked.
    check_accepted_request(before, was, r, report);
    if (::testing::Test::HasFatalFailure()) return;
    ASSERT_TRUE(r.move ? now.position.x == r.target_x_m && now.position.y == r.target_y_m : now.position.x == was.position.x && now.position.y == was.position.y)
        << report();
    double volume = 0.0;
    for (const Deposition& d : r.depositions) {
      expected(d.row, d.col) += d.height_m;
      if (before.deposit_bound.size() > 0) {  // rule 3.5b: at most 0.1 eps above the deposit bound
        ASSERT_LE(expected(d.row, d.col), before.deposit_bound(d.row, d.col) +
                                              0.1 * construction_params(was.type).eps_m + tol::kLengthM)
            << report();
      }
      expected_depositor[static_cast<std::size_t>(d.row) * expected.cols() + d.col] = was.id;
      volume += d.height_m * expected.cell_size_m() * expected.cell_size_m();
    }
    // Deposits: each shape on the terrain as the ones before it left it; on the grid, no cell under this robot,
    // no cell raised more than 1 m by the request, the volume the deposit's within the cone's tolerance.
    std::map<std::pair<int, int>, double> raised;
    deposit_requests += r.deposits.empty() ? 0 : 1;
    for (const Deposit& d : r.deposits) {
      const bool cube = was.type.depositor.kind == DepositorKind::kCube;
      const double side = depositor_cube_size_m(was.type);
      const DepositShape shape =
          cube ? cube_column_shape(expected.geometry(), d.centre, side,
                                   static_cast<int>(std::round(d.volume_m3 / (side * side * side))))
               : cone_pile_shape(expected, d.centre, d.volume_m3, was.type.depositor.repose_deg);
      ASSERT_TRUE(shape.on_grid) << report();
      ASSERT_NEAR(shape.volume_m3, d.volume_m3, 1e-9 * d.volume_m3 + 1e-15) << report();
      for (const CellRise& c : shape.rises) {
        const Position p = expected.cell_center(c.cell);
        ASSERT_GT(distance(p.x, p.y, now.position.x, now.position.y), 0.5 * body.navigability.delta_m) << report();
        const double total = raised[std::make_pair(c.cell.row, c.cell.col)] += c.rise_m;
        ASSERT_LE(total, 1.0 + tol::kLengthM) << report();
        expected(c.cell) += c.rise_m;
        if (before.deposit_bound.size() > 0) {  // rule 3d.10: at most 0.1 eps above the deposit bound
          ASSERT_LE(expected(c.cell), before.deposit_bound(c.cell) + 0.1 * construction_params(was.type).eps_m +
                                          tol::kLengthM)
              << report();
        }
        expected_depositor[static_cast<std::size_t>(c.cell.row) * expected.cols() + c.cell.col] = was.id;
        volume += c.rise_m * expected.cell_size_m() * expected.cell_size_m();
      }
    }
    added_volume += volume;
    const double material = r.refill ? body.material_capacity_m3 : std::max(0.0, was.material_m3 - volume);
    ASSERT_NEAR(now.material_m3, material, 1e-12) << report();
    ASSERT_NEAR(now.deposited_m3 - was.deposited_m3, volume, 1e-12) << report();
  }
  ASSERT_EQ(outcome.accepted, accepted) << report();
  ASSERT_EQ(state.unattributed_rejections - before.unattributed_rejections, unattributed(before, submissions))
      << report();
  ASSERT_EQ(outcome.rejected, rejected + unattributed(before, submissions)) << report();
  ASSERT_EQ(outcome.missed, missed) << report();

  // The terrain changed exactly at the accepted cells, by exactly their heights, and stays finite.
  for (long long i = 0; i < expected.size(); ++i) {
    const double h = state.terrain.data()[i];
    ASSERT_TRUE(std::isfinite(h)) << "cell " << i << " = " << h << "\n" << report();
    ASSERT_EQ(std::memcmp(&h, &expected.data()[i], sizeof h), 0)
        << "cell " << i << ": " << h << ", expected " << expected.data()[i] << "\n"
        << report();
    if (expected_depositor[static_cast<std::size_t>(i)] != 0) {
      ASSERT_EQ(state.depositor.data()[i], expected_depositor[static_cast<std::size_t>(i)]) << report();
    }
  }
  ASSERT_NEAR(state.deposited_volume_m3 - before.deposited_volume_m3, added_volume,
              1e-12 * (1.0 + before.deposited_volume_m3))
      << report();
  for (const AgentRecord& a : state.agents) {
    if (!a.alive) continue;
    ASSERT_TRUE(state.terrain.cell_at(a.position)) << "agent " << a.id << " off the grid\n" << report();
  }
}

TEST(WorldRequestFuzz, ValidationNeverThrowsAndStepsChangeExactlyWhatTheyAccept) {
  const std::uint64_t seed = fuzz::seed(0xA4B17E4);
  const int worlds = fuzz::iterations(2000);
  constexpr int kStepsPerWorld = 24;
  WorldFuzzer fuzzer(seed);
  fuzz::Watchdog watchdog;
  long long accepted = 0, rejected = 0, deposited = 0, deposit_requests = 0;
  for (int w = 0; w < worlds; ++w) {
    WorldState state = fuzzer.make_world();
    for (int k = 0; k < kStepsPerWorld && !state.live_ids().empty(); ++k) {
      const std::vector<Submission> submissions = fuzzer.submissions(state);
      const std::string where =
          "world seed " + std::to_string(seed) + " world " + std::to_string(w) + " step " + std::to_string(k);
      const WorldState copy = state;
      const double volume = state.deposited_volume_m3;
      watchdog.arm(std::chrono::seconds(5), where, describe(state, submissions),
                   fuzz::failure_path("world", seed, w, ".txt"));
      check_step(state, submissions, [&] { return where + ": " + describe(copy, submissions); }, deposit_requests);
      watchdog.disarm();
      if (::testing::Test::HasFailure()) return;
      for (std::size_t i = 0; i < state.agents.size(); ++i) {
        accepted += state.agents[i].accepted - copy.agents[i].accepted;
        rejected += state.agents[i].rejected - copy.agents[i].rejected;
      }
      deposited += state.deposited_volume_m3 > volume ? 1 : 0;
    }
  }
  // The fuzzer must reach the interesting paths: accepted motions and depositions as well as rejections.
  EXPECT_GT(accepted, worlds) << "accepted " << accepted;
  EXPECT_GT(deposited, worlds / 2) << "steps with depositions: " << deposited;
  EXPECT_GT(rejected, worlds) << "rejected " << rejected;
  EXPECT_GT(deposit_requests, worlds / 4) << "accepted requests with cube or cone deposits: " << deposit_requests;
  RecordProperty("deposit_requests", static_cast<int>(deposit_requests));
  RecordProperty("accepted", static_cast<int>(accepted));
  RecordProperty("rejected", static_cast<int>(rejected));
  RecordProperty("steps_with_depositions", static_cast<int>(deposited));
}

}  // namespace
}  // namespace marsala::world_server
