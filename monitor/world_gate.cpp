#include "marsala/monitor/world_gate.hpp"

#include <fmt/format.h>

#include <cstdlib>

#include "marsala/core/error.hpp"
#include "marsala/monitor/format.hpp"
#include "marsala/protocol/world_proof.hpp"

namespace marsala::monitor {

std::vector<protocol::WorldStatus> WorldGate::statuses(std::vector<bus::Received<protocol::WorldStatus>> batch) {
  std::vector<protocol::WorldStatus> believed;
  for (bus::Received<protocol::WorldStatus>& r : batch) {
    const std::string run = printable(r.sample.run_id);
    if (!proven(r.sample, r.from)) {
      report("statuses", r.from, fmt::format("another world/publisher of run '{}': no proof of its world", run));
      continue;
    }
    if (!world_key_.empty() && r.sample.world_key != world_key_) {
      report("statuses", r.from,
             fmt::format("another world/publisher of run '{}': not the run's key (MARSALA_RUN_KEY)", run));
      continue;
    }
    const auto pinned = worlds_.find(r.sample.run_id);
    if (pinned == worlds_.end()) {
      worlds_.emplace(r.sample.run_id, World{r.from, r.sample.world_key, r.sample.step});
    } else if (World& world = pinned->second; r.from == world.writer) {
      world.last_step = std::max(world.last_step, r.sample.step);
    } else if (r.sample.world_key == world.key && r.sample.step >= world.last_step) {
      err_ << fmt::format("marsala-monitor: run '{}' continues from participant {} at step {} (its world was {}; "
                          "the same run key)\n",
                          run, r.from.to_string(), r.sample.step, world.writer.to_string());
      world = World{r.from, r.sample.world_key, r.sample.step};
    } else {
      const std::string why =
          r.sample.world_key != world.key
              ? fmt::format("another world/publisher of run '{}' (its world is participant {}, with another key)", run,
                            world.writer.to_string())
              : fmt::format("run '{}' went back to step {} (its world is at step {})", run, r.sample.step,
                            world.last_step);
      report("statuses", r.from, why);
      continue;
    }
    believed.push_back(std::move(r.sample));
  }
  return believed;
}

std::string WorldGate::world_key_from_environment() {
  const char* path = std::getenv("MARSALA_RUN_KEY");
  if (path == nullptr || *path == '\0') return {};
  try {
    return protocol::world_key_of(protocol::load_run_key(path));
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(fmt::format("MARSALA_RUN_KEY {}", e.what()));
  }
}

bool WorldGate::proven(const protocol::WorldStatus& s, const bus::WriterId& from) {
  const std::string id = fmt::format("{}\n{}\n{}\n{}", from.to_string(), s.run_id, s.world_key, s.world_proof);
  if (proofs_.count(id) != 0) return true;
  if (!protocol::world_proven(s.world_key, s.world_proof, s.run_id, from.prefix)) return false;
  if (proofs_.size() >= kMaxProofs) proofs_.clear();
  proofs_.insert(id);
  return true;
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
