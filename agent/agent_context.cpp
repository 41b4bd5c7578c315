#include "marsala/agent/agent_context.hpp"

#include <cmath>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::agent {

NavigabilityParams construction_params(const AgentContext& context) {
  const Task& t = context.task;
  return {t.construction_kappa.value_or(context.body.navigability.kappa), t.construction_width_m.value_or(context.body.navigability.delta_m),
          t.construction_eps_m.value_or(context.body.navigability.eps_m)};
}

double neighbour_keep_out_m(double max_delta_m, double max_step_m) { return 0.5 * max_delta_m + max_step_m + 1e-6; }

}  // namespace marsala::agent
