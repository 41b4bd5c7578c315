#include "marsala/world_server/runtime/request_collector.hpp"

#include <algorithm>
#include <utility>

namespace marsala::world_server {

void RequestCollector::read_partitions(const WorldState& state, RequestSelection& selection, Collected& into) {
  for (const AgentRecord& a : state.agents) {
    std::vector<protocol::ActionRequest> received = links_.take(a.id);
    if (!a.alive) continue;  // a dropped agent's requests are read only to be discarded
    for (protocol::ActionRequest& r : received) {
      const bool answers = r.step == state.step && carries_identity_of(a, r);
      const RequestTake take = selection.take(a.id, answers);
      if (take == RequestTake::kAnswer) into.answered_at.emplace_back(a.id, Clock::now());
      if (take != RequestTake::kSurplus) into.submissions.push_back({a.id, std::move(r)});
    }
  }
}

Collected RequestCollector::collect(const WorldState& state, double deadline_s, const std::atomic<bool>& stop,
                                    const CollectDuties& duties) {
  Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(deadline_s));
  Clock::time_point last_wake = Clock::now();
  Clock::time_point next_resend = Clock::now() + kResendInterval;
  RequestSelection selection(state.agents.size());
  Collected collected;
  for (;;) {
    duties.on_wake();
    read_partitions(state, selection, collected);
    const Clock::time_point now = Clock::now();
    if (now >= next_liveliness_check_) {
      duties.check_liveliness();
      next_liveliness_check_ = now + kLivelinessPoll;
    }
    // A wait lasts at most kPollInterval: a longer gap is time this process did not run, in which no agent could be
    // heard; a held step waits for its team without a deadline. Neither is charged to the agents.
    if (now - last_wake >= kWorldPause || (duties.held && duties.held())) deadline += now - last_wake;
    last_wake = now;
    const std::vector<std::uint32_t> live = state.live_ids();
    if (selection.all_answered(live)) break;
    if (stop || now >= deadline) break;
    if (now >= next_resend) {
      for (std::uint32_t id : live)
        if (!selection.answered(id) && !links_.resend(id, state.step))
          duties.send_frame(id);  // admitted during this step (re-admission, takeover): its first frame of it
      next_resend = now + kResendInterval;
    }
    signal_->wait_until(std::min({deadline, next_resend, now + Clock::duration(kPollInterval)}));
    collected.waited += Clock::now() - now;
  }
  collected.surplus = selection.surplus();
  return collected;
}

}  // namespace marsala::world_server
