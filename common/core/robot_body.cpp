#include "marsala/core/robot_body.hpp"

#include <cmath>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"

namespace marsala {
namespace {

/// Empty when v is finite, |v| < kMaxMagnitude and v > 0 (strict) or v >= 0.
std::string check(const char* name, double v, bool strictly_positive, const char* unit) {
  const bool in_range = std::isfinite(v) && std::abs(v) < kMaxMagnitude && (strictly_positive ? v > 0.0 : v >= 0.0);
  if (in_range) return {};
  return fmt::format("{} = {}: must be finite, {} and < 1e6 [{}]", name, v, strictly_positive ? "> 0" : ">= 0", unit);
}

}  // namespace

bool operator==(const RobotBody& a, const RobotBody& b) {
  return a.navigability == b.navigability && a.max_step_m == b.max_step_m && a.max_deposit_m3 == b.max_deposit_m3 &&
         a.material_capacity_m3 == b.material_capacity_m3 && a.reach_m == b.reach_m &&
         a.sensing_range_m == b.sensing_range_m && a.proximity_range_m == b.proximity_range_m &&
         a.cube_size_m == b.cube_size_m;
}

std::string body_problem(const RobotBody& b) {
  const NavigabilityParams& n = b.navigability;
  for (const std::string& problem :
       {check("kappa", n.kappa, true, "m/m"), check("delta_m", n.delta_m, true, "m"),
        check("eps_m", n.eps_m, false, "m"), check("max_step_m", b.max_step_m, true, "m"),
        check("max_deposit_m3", b.max_deposit_m3, true, "m^3"),
        check("material_capacity_m3", b.material_capacity_m3, false, "m^3"), check("reach_m", b.reach_m, false, "m"),
        check("sensing_range_m", b.sensing_range_m, false, "m"),
        check("proximity_range_m", b.proximity_range_m, false, "m"), check("cube_size_m", b.cube_size_m, true, "m")})
    if (!problem.empty()) return problem;
  // The world judges a motion by the cells the robot's centre passes through, each standing for the body's ball;
  // a step of at most half the body keeps the balls at its two ends overlapping.
  if (b.max_step_m > 0.5 * n.delta_m + 1e-9)
    return fmt::format("max_step_m = {}: exceeds half the body length (delta_m / 2 = {} m) [m]", b.max_step_m,
                       0.5 * n.delta_m);
  return {};
}

double cube_layer_m(double cube_size_m, double cell_size_m) {
  if (!(cube_size_m > 0.0) || !std::isfinite(cube_size_m) || !(cell_size_m > 0.0) || !std::isfinite(cell_size_m))
    throw InvalidArgument(
        fmt::format("cube size {} m and cell size {} m must be finite and > 0", cube_size_m, cell_size_m));
  return cube_size_m * cube_size_m * cube_size_m / (cell_size_m * cell_size_m);
}

}  // namespace marsala
