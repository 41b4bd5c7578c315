#pragma once
// Plausibility of a robot body: shared by scenario validation (a bad value is an error naming the field) and the
// world's admission (a bad hello is refused with the same words).

#include <string>

#include "common/bus/messages.hpp"

namespace marsala::scenario {

/// Largest magnitude any length, volume or slope may have [m, m^3, m/m]; beyond it a value is absurd.
inline constexpr double kMaxMagnitude = 1e6;

/// Empty when every field of `body` is finite, below kMaxMagnitude in magnitude and in its range (kappa, delta_m,
/// max_step_m, max_deposit_m3, cube_size_m > 0; the other fields >= 0); otherwise the first problem, e.g.
/// "kappa = nan: must be finite and > 0 [m/m]".
std::string body_problem(const bus::BodyParams& body);

/// True when two bodies are equal field by field (bit for bit, as both sides read the same scenario file).
bool same_body(const bus::BodyParams& a, const bus::BodyParams& b);

}  // namespace marsala::scenario
