#include "marsala/world_server/rules/stall_watch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace marsala::world_server {
namespace {

/// What a step did: its progress after it and whether it changed the terrain.
struct Activity {
  double progress = 0.0;
  bool terrain_changed = false;
};

/// An independent reference: the first next_step at which `limit` steps in a row had neither a progress above every
/// earlier one (the start's included) nor a terrain change; 0 when that never happens within `steps`.
std::uint64_t first_stall_by_scan(const std::vector<Activity>& steps, double start_progress, std::uint64_t limit) {
  double best = start_progress;
  std::uint64_t run = 0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const bool active = steps[k].terrain_changed || steps[k].progress > best + 1e-12;
    best = std::max(best, steps[k].progress);
    run = active ? 0 : run + 1;
    if (run >= limit) return k + 1;
  }
  return 0;
}

std::uint64_t first_stall_by_watch(const std::vector<Activity>& steps, double start_progress, std::uint64_t limit) {
  StallWatch watch;
  watch.best_progress = start_progress;
  for (std::uint64_t next = 0; next <= steps.size(); ++next) {
    if (stalled(watch, next, limit)) return next;
    if (next < steps.size()) observe_step(watch, next, steps[next].progress, steps[next].terrain_changed);
  }
  return 0;
}

TEST(StallWatch, QuietStepsCountFromTheLastActivity) {
  StallWatch w;
  EXPECT_EQ(quiet_steps(w, 0), 0u);
  observe_step(w, 0, 0.0, false);
  observe_step(w, 1, 0.0, false);
  EXPECT_EQ(quiet_steps(w, 2), 2u);
  EXPECT_FALSE(stalled(w, 2, 3));
  observe_step(w, 2, 0.0, true);  // a deposit: a new quiet stretch starts at step 3
  EXPECT_EQ(w.quiet_since, 3u);
  EXPECT_EQ(quiet_steps(w, 3), 0u);
  for (std::uint64_t s = 3; s < 6; ++s) observe_step(w, s, 0.0, false);
  EXPECT_TRUE(stalled(w, 6, 3));
  EXPECT_FALSE(stalled(w, 6, 4));
  EXPECT_FALSE(stalled(w, 6, 0));  // 0: never
  EXPECT_EQ(w.longest_quiet, 3u);
}

TEST(StallWatch, OnlyAProgressAboveTheBestSoFarCounts) {
  StallWatch w;
  observe_step(w, 0, 0.5, false);  // rises from 0
  EXPECT_EQ(w.quiet_since, 1u);
  observe_step(w, 1, 0.25, false);         // falls (an agent left the goal)
  observe_step(w, 2, 0.5, false);          // back to the best: no rise
  observe_step(w, 3, 0.5 + 1e-13, false);  // rounding, no rise
  EXPECT_EQ(w.quiet_since, 1u);
  EXPECT_EQ(quiet_steps(w, 4), 3u);
  observe_step(w, 4, 0.75, false);
  EXPECT_EQ(w.quiet_since, 5u);
  EXPECT_DOUBLE_EQ(w.best_progress, 0.75);
}

TEST(StallWatch, AgreesWithAScanOnRandomHistories) {
  std::uint64_t state = 12345;
  const auto next = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return state >> 33;
  };
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Activity> steps(static_cast<std::size_t>(1 + next() % 80));
    double p = 0.0;
    for (Activity& a : steps) {
      const auto roll = next() % 10;
      if (roll == 0) p = std::min(1.0, p + 0.1);
      if (roll == 1) p = std::max(0.0, p - 0.1);
      a.progress = p;
      a.terrain_changed = next() % 12 == 0;
    }
    const double start = (next() % 3) * 0.1;
    const std::uint64_t limit = 1 + next() % 15;
    EXPECT_EQ(first_stall_by_watch(steps, start, limit), first_stall_by_scan(steps, start, limit))
        << "trial " << trial << ", limit " << limit;
  }
}

}  // namespace
}  // namespace marsala::world_server
