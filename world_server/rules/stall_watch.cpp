#include "marsala/world_server/rules/stall_watch.hpp"

#include <algorithm>

namespace marsala::world_server {

void observe_step(StallWatch& watch, std::uint64_t step, double progress, bool terrain_changed) {
  const bool rose = progress > watch.best_progress + kProgressRiseEpsilon;
  if (rose) watch.best_progress = progress;
  if (rose || terrain_changed) {
    watch.quiet_since = step + 1;
    return;
  }
  watch.longest_quiet = std::max(watch.longest_quiet, quiet_steps(watch, step + 1));
}

std::uint64_t quiet_steps(const StallWatch& watch, std::uint64_t next_step) {
  return next_step > watch.quiet_since ? next_step - watch.quiet_since : 0;
}

bool stalled(const StallWatch& watch, std::uint64_t next_step, std::uint64_t stall_steps) {
  return stall_steps > 0 && quiet_steps(watch, next_step) >= stall_steps;
}

}  // namespace marsala::world_server
