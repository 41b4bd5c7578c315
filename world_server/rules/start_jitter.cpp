#include "marsala/world_server/rules/start_jitter.hpp"

#include <cmath>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/random.hpp"
#include "marsala/core/cell_occupancy.hpp"

namespace marsala::world_server {

Position jittered_start(const Heightmap& terrain, const scenario::AgentSlot& slot, const RobotBody& body,
                        double jitter_m, std::uint64_t seed) {
  if (!(jitter_m >= 0.0) || !std::isfinite(jitter_m))
    throw InvalidArgument(fmt::format("start jitter of agent {} must be finite and >= 0 m", slot.id));
  const Position start = slot.start;
  if (jitter_m == 0.0) return start;
  // Streams of different agents start at unrelated points of the generator's cycle.
  random::Rng rng(random::mix64(random::mix64(seed) + slot.id));
  const NavigabilityParams params{body.navigability.kappa, body.navigability.delta_m, body.navigability.eps_m};
  for (int draw = 0; draw < kMaxJitterDraws; ++draw) {
    double dx = 0.0, dy = 0.0;
    do {  // uniform in the unit disc: 4 / pi tries on average
      dx = rng.uniform(-1.0, 1.0);
      dy = rng.uniform(-1.0, 1.0);
    } while (dx * dx + dy * dy > 1.0);
    const Position p{start.x + jitter_m * dx, start.y + jitter_m * dy};
    const auto cell = terrain.cell_at(p);
    if (cell && cell_occupiable(terrain, *cell, params)) return p;
  }
  return start;
}

}  // namespace marsala::world_server
