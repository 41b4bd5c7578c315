#include "marsala/agent/executive/pose_error.hpp"

#include <cmath>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala::agent::executive {

PoseError::PoseError(const Localisation& spec, std::uint64_t seed)
    : spec_(spec), rng_(random::derive_seed(seed, 0x706f73655f657272ULL)) {
  if (!std::isfinite(spec.noise_sd_m) || spec.noise_sd_m < 0.0 || spec.noise_sd_m > 10.0)
    throw InvalidArgument(fmt::format("localisation: noise_sd_m = {} must be in [0, 10] m", spec.noise_sd_m));
  if (!std::isfinite(spec.correlation_steps) || spec.correlation_steps < 1.0 || spec.correlation_steps > 1e5)
    throw InvalidArgument(
        fmt::format("localisation: correlation_steps = {} must be in [1, 1e5]", spec.correlation_steps));
  decay_ = std::exp(-1.0 / spec.correlation_steps);
  drive_ = std::sqrt(1.0 - decay_ * decay_) * spec.noise_sd_m;
}

double PoseError::normal() {
  // Box-Muller on (0, 1] x [0, 1): never log(0).
  const double u = 1.0 - rng_.uniform();
  const double v = rng_.uniform();
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * M_PI * v);
}

Position PoseError::at(std::uint64_t step) {
  if (!active()) return {};
  if (!started_) {
    error_ = {spec_.noise_sd_m * normal(), spec_.noise_sd_m * normal()};
    started_ = true;
    step_ = step;
    return error_;
  }
  if (step < step_) throw InvalidArgument(fmt::format("localisation: step {} comes after step {}", step, step_));
  // A gap beyond kMaxDrawnGap steps is one fresh draw (the error has long forgotten its past by then).
  const std::uint64_t gap = step - step_;
  if (gap > kMaxDrawnGap) {
    error_ = {spec_.noise_sd_m * normal(), spec_.noise_sd_m * normal()};
  } else {
    for (std::uint64_t k = 0; k < gap; ++k) {
      const double nx = normal(), ny = normal();
      error_ = {decay_ * error_.x + drive_ * nx, decay_ * error_.y + drive_ * ny};
    }
  }
  step_ = step;
  return error_;
}

}  // namespace marsala::agent::executive
