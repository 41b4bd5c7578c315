#include "world_server/start_jitter.hpp"

#include <cmath>
#include <string>

#include "common/error.hpp"
#include "world_server/arbiter.hpp"

namespace marsala::world_server {
namespace {

std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// splitmix64; doubles from the top 53 bits (exact conversion).
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() { return mix64(state_ += 0x9e3779b97f4a7c15ULL); }
  /// Uniform in [-1, 1).
  double symmetric() { return static_cast<double>(next() >> 11) * 0x1.0p-52 - 1.0; }

 private:
  std::uint64_t state_;
};

}  // namespace

Position jittered_start(const grid::Heightmap& terrain, const scenario::AgentSlot& slot, const bus::BodyParams& body,
                        double jitter_m, std::uint64_t seed) {
  if (!(jitter_m >= 0.0) || !std::isfinite(jitter_m))
    throw InvalidArgument("start jitter of agent " + std::to_string(slot.id) + " must be finite and >= 0 m");
  const Position start{slot.start_x_m, slot.start_y_m};
  if (jitter_m == 0.0) return start;
  // Streams of different agents start at unrelated points of the generator's cycle.
  SplitMix64 rng(mix64(mix64(seed) + slot.id));
  const NavigabilityParams params{body.kappa, body.delta_m, body.eps_m};
  for (int draw = 0; draw < kMaxJitterDraws; ++draw) {
    double dx = 0.0, dy = 0.0;
    do {  // uniform in the unit disc: 4 / pi tries on average
      dx = rng.symmetric();
      dy = rng.symmetric();
    } while (dx * dx + dy * dy > 1.0);
    const Position p{start.x + jitter_m * dx, start.y + jitter_m * dy};
    const auto cell = terrain.cell_at(p);
    if (cell && cell_occupiable(terrain, *cell, params)) return p;
  }
  return start;
}

}  // namespace marsala::world_server
