#include "marsala/world_server/rules/initial_state.hpp"

#include <vector>

#include "marsala/world_server/rules/completion.hpp"
#include "marsala/world_server/rules/start_jitter.hpp"

namespace marsala::world_server {

WorldState make_world_state(const scenario::Scenario& scenario, Heightmap terrain, std::uint32_t agent_count) {
  check_agent_count(scenario, agent_count);
  std::vector<Position> starts;
  starts.reserve(agent_count);
  for (std::uint32_t id = 1; id <= agent_count; ++id)
    starts.push_back(jittered_start(terrain, scenario.slots[id - 1], scenario.robot_for(id).body,
                                    scenario.start_jitter_m, scenario.seed));
  WorldState state = world_state_at(scenario, std::move(terrain), starts);
  start_completion_check(state);
  state.stall.best_progress = progress(state);  // a rise counts from where the run starts
  return state;
}

}  // namespace marsala::world_server
