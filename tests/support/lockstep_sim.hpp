#pragma once
// A whole run in one process: the world's own rules (initial state, admission, sensing, apply_step) and one real
// behaviour per agent (make_robot_behaviour, as marsala-agent makes it), stepped in lockstep without a bus. Every
// agent answers every frame in time, so a run gives the terrain the processes give over DDS; tests use it for
// hundreds of short runs (liveness), tools for sweeps and for looking inside a run at a chosen step.

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "marsala/agent/agent_context.hpp"
#include "marsala/agent/reactive/behaviour.hpp"
#include "marsala/core/cpu_time.hpp"
#include "marsala/core/error.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/world_server/rules/admission.hpp"
#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/initial_state.hpp"
#include "marsala/world_server/rules/sensing_service.hpp"
#include "marsala/world_server/rules/step.hpp"

namespace marsala::test {

/// One run's world and agents, stepped in-process.
class LockstepSim {
 public:
  /// The run of `scenario` (its seed) on `terrain` with agents 1..agent_count, every one admitted; the agents keep
  /// the right-of-way protocol (AgentContext::right_of_way) when the scenario's right_of_way and `right_of_way` are.
  LockstepSim(const scenario::Scenario& scenario, Heightmap terrain, std::uint32_t agent_count,
              bool right_of_way = true)
      : state_(world_server::make_world_state(scenario, std::move(terrain), agent_count)) {
    double max_delta = 0.0, max_step = 0.0;
    for (const auto& a : state_.agents) {
      max_delta = std::max(max_delta, a.type.body.navigability.delta_m);
      max_step = std::max(max_step, a.type.body.max_step_m);
    }
    for (const auto& a : state_.agents) {
      agent::AgentContext context;
      context.agent_id = a.id;
      context.session = 1000 + a.id;
      context.type = a.type;
      context.neighbour_keep_out_m = agent::neighbour_keep_out_m(max_delta, max_step);
      context.seed = scenario.seed;
      context.right_of_way = right_of_way && scenario.right_of_way;
      if (scenario.has_goal_vector_map) context.goal_vector_map = scenario.goal_vector_map;
      protocol::AgentHello hello;
      hello.agent_id = a.id;
      hello.session = context.session;
      hello.name = fmt::format("{}-{}", a.type.name, a.id);
      hello.behaviour = a.type.behaviour;
      hello.body = a.type.body;
      const auto decision = world_server::decide_admission(state_, hello, false);
      if (!decision.accepted) throw InvalidArgument(fmt::format("agent {}: {}", a.id, decision.reason));
      world_server::admit(state_, hello, decision.kind);
      auto behaviour = agent::reactive::make_robot_behaviour(context);
      behaviour->on_admission(world_server::admission_message(state_, hello, decision, "sim"));
      behaviours_.push_back(std::move(behaviour));
    }
    sensing_.emplace(state_);
  }

  const world_server::WorldState& state() const { return state_; }
  /// The behaviour of agent `id` (1-based).
  const agent::reactive::Behaviour& behaviour(std::uint32_t id) const { return *behaviours_.at(id - 1); }
  /// The requests of the last step, by agent id - 1.
  const std::vector<protocol::ActionRequest>& last_requests() const { return requests_; }

  /// What one live agent's part of a step cost [ms, CPU time of this thread]: the world's frame for it (a scanning
  /// robot's ray casting) and its behaviour's decision on that frame (mapping included), and the frame itself.
  struct AgentStepCost {
    std::uint32_t agent_id = 0;
    double frame_ms = 0.0;
    double decide_ms = 0.0;
    protocol::SensorFrame frame;
  };
  /// step(), recording each live agent's costs in `costs` (cleared first); for benchmarks.
  world_server::StepOutcome step_timed(std::vector<AgentStepCost>& costs) {
    requests_.clear();
    costs.clear();
    for (std::uint32_t id : state_.live_ids()) {
      AgentStepCost cost;
      cost.agent_id = id;
      double began = thread_cpu_ms();
      cost.frame = sensing_->frame_for(state_, id);
      cost.frame_ms = thread_cpu_ms() - began;
      began = thread_cpu_ms();
      requests_.push_back(behaviours_[id - 1]->decide(cost.frame));
      cost.decide_ms = thread_cpu_ms() - began;
      costs.push_back(std::move(cost));
    }
    return world_server::apply_step(state_, requests_);
  }

  /// One lockstep step: every live agent's frame, its request, the world's step.
  world_server::StepOutcome step() {
    requests_.clear();
    for (std::uint32_t id : state_.live_ids())
      requests_.push_back(behaviours_[id - 1]->decide(sensing_->frame_for(state_, id)));
    return world_server::apply_step(state_, requests_);
  }

 private:
  world_server::WorldState state_;
  std::optional<world_server::SensingService> sensing_;
  std::vector<std::unique_ptr<agent::reactive::Behaviour>> behaviours_;
  std::vector<protocol::ActionRequest> requests_;
};

}  // namespace marsala::test
