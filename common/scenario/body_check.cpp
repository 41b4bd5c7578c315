#include "common/scenario/body_check.hpp"

#include <cmath>
#include <cstdio>

namespace marsala::scenario {
namespace {

std::string format(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// Empty when v is finite, |v| < kMaxMagnitude and v > 0 (strict) or v >= 0.
std::string check(const char* name, double v, bool strictly_positive, const char* unit) {
  const bool in_range = std::isfinite(v) && std::abs(v) < kMaxMagnitude && (strictly_positive ? v > 0.0 : v >= 0.0);
  if (in_range) return {};
  return std::string(name) + " = " + format(v) + ": must be finite, " + (strictly_positive ? "> 0" : ">= 0") +
         " and < 1e6 [" + unit + "]";
}

}  // namespace

std::string body_problem(const bus::BodyParams& b) {
  for (const std::string& problem :
       {check("kappa", b.kappa, true, "m/m"), check("delta_m", b.delta_m, true, "m"), check("eps_m", b.eps_m, false, "m"),
        check("max_step_m", b.max_step_m, true, "m"), check("max_deposit_m3", b.max_deposit_m3, true, "m^3"),
        check("material_capacity_m3", b.material_capacity_m3, false, "m^3"), check("reach_m", b.reach_m, false, "m"),
        check("sensing_range_m", b.sensing_range_m, false, "m"),
        check("proximity_range_m", b.proximity_range_m, false, "m"), check("cube_size_m", b.cube_size_m, true, "m")})
    if (!problem.empty()) return problem;
  return {};
}

bool same_body(const bus::BodyParams& a, const bus::BodyParams& b) {
  return a.kappa == b.kappa && a.delta_m == b.delta_m && a.eps_m == b.eps_m && a.max_step_m == b.max_step_m &&
         a.max_deposit_m3 == b.max_deposit_m3 && a.material_capacity_m3 == b.material_capacity_m3 &&
         a.reach_m == b.reach_m && a.sensing_range_m == b.sensing_range_m &&
         a.proximity_range_m == b.proximity_range_m && a.cube_size_m == b.cube_size_m;
}

}  // namespace marsala::scenario
