#pragma once
// Localisation error (docs/runtime.md#localisation-error): how far the pose a robot believes lies from its true one.
// Per axis a first-order Gauss-Markov process over the lockstep steps, e_k = a e_(k-1) + sqrt(1 - a^2) sd n_k with
// a = exp(-1 / correlation_steps) and n_k standard normal; e_0 is drawn from the stationary distribution N(0, sd^2),
// so the error has standard deviation sd at every step and drifts rather than jumps. Normals come from the portable
// generator (common/core/random.hpp) by Box-Muller, so a seed gives the same errors on every machine.

#include <cstdint>

#include "marsala/core/random.hpp"
#include "marsala/core/robot_type.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::executive {

/// The localisation error of one robot, step by step.
class PoseError {
 public:
  /// Throws InvalidArgument when noise_sd_m is not finite and in [0, 10] or correlation_steps not in [1, 1e5].
  PoseError(const Localisation& spec, std::uint64_t seed);

  /// Steps skipped between two calls are drawn too, up to this many; a longer gap is one fresh stationary draw.
  static constexpr std::uint64_t kMaxDrawnGap = 1'000'000;

  /// The error at `step` [m] (believed = true + error); steps skipped since the last call are drawn too (up to
  /// kMaxDrawnGap), so the error at a step does not depend on which steps the robot saw. Throws InvalidArgument for
  /// a step before the last one asked.
  Position at(std::uint64_t step);
  /// False when the spec's sd is 0 (the error is always (0, 0)).
  bool active() const { return spec_.noise_sd_m > 0.0; }
  const Localisation& spec() const { return spec_; }

 private:
  double normal();

  Localisation spec_;
  random::Rng rng_;
  double decay_ = 0.0;  ///< a
  double drive_ = 0.0;  ///< sqrt(1 - a^2) sd [m]
  bool started_ = false;
  std::uint64_t step_ = 0;
  Position error_;
};

}  // namespace marsala::agent::executive
