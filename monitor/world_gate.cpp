#include "marsala/monitor/world_gate.hpp"

#include <fmt/format.h>

#include "marsala/monitor/format.hpp"

namespace marsala::monitor {

std::vector<protocol::WorldStatus> WorldGate::statuses(std::vector<bus::Received<protocol::WorldStatus>> batch,
                                                       Clock::time_point now) {
  std::vector<protocol::WorldStatus> believed;
  for (bus::Received<protocol::WorldStatus>& r : batch) {
    const auto pinned = worlds_.find(r.sample.run_id);
    if (pinned == worlds_.end()) {
      worlds_.emplace(r.sample.run_id, World{r.from, r.sample.step, now});
    } else if (World& world = pinned->second; r.from == world.writer) {
      world.last_step = std::max(world.last_step, r.sample.step);
      world.last_heard = now;
    } else if (now - world.last_heard >= kWorldSilence && r.sample.step >= world.last_step) {
      err_ << fmt::format("marsala-monitor: run '{}' continues from participant {} at step {} (its world was {})\n",
                          printable(r.sample.run_id), r.from.to_string(), r.sample.step, world.writer.to_string());
      world = World{r.from, r.sample.step, now};
    } else {
      const std::string why = r.sample.step < world.last_step
                                  ? std::string(", and its step went back")
                                  : fmt::format(", which is alive (last heard at step {})", world.last_step);
      report("statuses", r.from,
             fmt::format("run '{}' is published by participant {}{}", printable(r.sample.run_id),
                         world.writer.to_string(), why));
      continue;
    }
    believed.push_back(std::move(r.sample));
  }
  return believed;
}

std::vector<protocol::WorldEvent> WorldGate::events(std::vector<bus::Received<protocol::WorldEvent>> batch) {
  for (bus::Received<protocol::WorldEvent>& r : batch) held_.push_back(std::move(r));
  std::vector<protocol::WorldEvent> believed;
  if (worlds_.empty()) {  // no world known yet: keep them (the latest kMaxHeldEvents) until a status names it
    if (held_.size() > kMaxHeldEvents)
      held_.erase(held_.begin(), held_.begin() + static_cast<std::ptrdiff_t>(held_.size() - kMaxHeldEvents));
    return believed;
  }
  for (bus::Received<protocol::WorldEvent>& r : held_) {
    bool pinned = false;
    for (const auto& [run, world] : worlds_) pinned = pinned || world.writer == r.from;
    if (!pinned) {
      report("events", r.from, "no run's world is that participant");
      continue;
    }
    believed.push_back(std::move(r.sample));
  }
  held_.clear();
  return believed;
}

void WorldGate::report(const std::string& what, const bus::WriterId& from, const std::string& why) {
  ++ignored_;
  if (reported_.insert(what + from.to_string()).second)
    err_ << fmt::format("marsala-monitor: ignoring {} from participant {}: {}\n", what, from.to_string(), why);
}

}  // namespace marsala::monitor
