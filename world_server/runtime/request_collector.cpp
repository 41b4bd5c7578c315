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
      if (take == RequestTake::kAnswer) {
        into.answered_at.push_back({a.id, Clock::now(), r.decision_us, r.decision_cpu_us});
        into.answers.push_back(into.submissions.size());
      }
      if (take != RequestTake::kSurplus) into.submissions.push_back({a.id, std::move(r)});
    }
  }
}

bool RequestCollector::look(const WorldState& state, const RequestSelection& selection, const CollectDuties& duties,
                            Clock::time_point now) {
  bool delivering = false;
  for (std::uint32_t id : state.live_ids()) {
    if (selection.answered(id)) continue;
    if (!links_.resend(id, state.step, now))
      duties.send_frame(id);  // admitted during this step (re-admission, takeover): its first frame of it
    else if (links_.in_flight(id))
      delivering = true;
  }
  return delivering;
}

Collected RequestCollector::collect(const WorldState& state, double deadline_s, const std::atomic<bool>& stop,
                                    const CollectDuties& duties, std::vector<Submission> standing) {
  Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(deadline_s));
  Clock::time_point last_wake = Clock::now();
  Clock::time_point next_look = last_wake;
  Clock::duration stretched{};  // deadline added for frames in flight
  bool delivering = false;      // at the latest look, a frame of an agent that has not answered was in flight
  RequestSelection selection(state.agents.size());
  Collected collected;
  for (Submission& s : standing) {
    selection.take(s.channel_id, true);
    collected.submissions.push_back(std::move(s));
  }
  for (;;) {
    duties.on_wake();
    read_partitions(state, selection, collected);
    const Clock::time_point now = Clock::now();
    if (now >= next_liveliness_check_) {
      duties.check_liveliness();
      next_liveliness_check_ = now + kLivelinessPoll;
    }
    // A wait lasts at most kPollInterval: a longer gap is time this process did not run, in which no agent could be
    // heard; a held step waits for its team without a deadline; a frame still in flight on a slow link has not
    // reached its agent. None of these is charged to the agents.
    if (now - last_wake >= kWorldPause || (duties.held && duties.held())) {
      deadline += now - last_wake;
    } else if (delivering && stretched < kMaxDeliveryStretch) {
      deadline += now - last_wake;
      stretched += now - last_wake;
    }
    last_wake = now;
    if (selection.all_answered(state.live_ids())) break;
    if (stop || now >= deadline) break;
    if (now >= next_look) {
      delivering = look(state, selection, duties, now);
      next_look = now + kResendLook;
    }
    signal_->wait_until(std::min({deadline, next_look, now + Clock::duration(kPollInterval)}));
    collected.waited += Clock::now() - now;
  }
  collected.surplus = selection.surplus();
  return collected;
}

}  // namespace marsala::world_server
