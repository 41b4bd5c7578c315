#include "world_server/completion.hpp"

#include "world_server/arbiter.hpp"

namespace marsala::world_server {

bool at_goal(const WorldState& state, const AgentRecord& agent) {
  constexpr double tol = arbiter_tolerance::kLengthM;
  const scenario::Goal& g = state.goal;
  const bool inside = agent.x_m >= g.x0_m - tol && agent.x_m <= g.x1_m + tol && agent.y_m >= g.y0_m - tol &&
                      agent.y_m <= g.y1_m + tol;
  if (!inside) return false;
  const double h = height_under(state.terrain, agent.x_m, agent.y_m);
  return h >= g.min_height_m - tol;  // false for NaN (off the grid)
}

bool is_completed(const WorldState& state) {
  bool any = false;
  for (const AgentRecord& a : state.agents) {
    if (!a.alive) continue;
    if (!at_goal(state, a)) return false;
    any = true;
  }
  return any;
}

double progress(const WorldState& state) {
  int live = 0, done = 0;
  for (const AgentRecord& a : state.agents) {
    if (!a.alive) continue;
    ++live;
    done += at_goal(state, a) ? 1 : 0;
  }
  return live == 0 ? 0.0 : static_cast<double>(done) / live;
}

}  // namespace marsala::world_server
