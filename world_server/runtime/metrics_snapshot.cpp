#include "marsala/world_server/runtime/metrics_snapshot.hpp"

#include "marsala/world_server/rules/completion.hpp"

namespace marsala::world_server {

void take_state(MetricsSnapshot& snapshot, const WorldState& state, const std::vector<bool>& connected) {
  snapshot.steps = state.step;
  snapshot.agents_expected = static_cast<std::uint32_t>(state.agents.size());
  snapshot.agents_admitted = snapshot.agents_live = snapshot.agents_connected = snapshot.agents_dropped = 0;
  snapshot.deadline_misses = snapshot.rejected_requests = 0;
  snapshot.agents.clear();
  for (const AgentRecord& a : state.agents) {
    AgentMetrics m;
    m.id = a.id;
    m.admitted = a.admitted;
    m.alive = a.alive;
    m.connected = a.alive && a.id <= connected.size() && connected[a.id - 1];
    m.accepted = a.accepted;
    m.rejected = a.rejected;
    m.missed = a.missed;
    m.deposited_m3 = a.deposited_m3;
    m.material_m3 = a.material_m3;
    snapshot.agents_admitted += m.admitted ? 1 : 0;
    snapshot.agents_live += m.alive ? 1 : 0;
    snapshot.agents_connected += m.connected ? 1 : 0;
    snapshot.agents_dropped += a.dropped ? 1 : 0;
    snapshot.deadline_misses += a.missed;
    snapshot.rejected_requests += a.rejected;
    snapshot.agents.push_back(m);
  }
  snapshot.unattributed_rejections = state.unattributed_rejections;
  snapshot.surplus_requests = state.surplus_requests;
  snapshot.progress = progress(state);
  snapshot.deposited_m3 = state.deposited_volume_m3;
}

}  // namespace marsala::world_server
