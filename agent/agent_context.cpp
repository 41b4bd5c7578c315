#include "marsala/agent/agent_context.hpp"

#include <cmath>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::agent {

GridGeometry world_geometry(const protocol::Admission& admission) {
  if (admission.rows <= 0 || admission.cols <= 0 || !(admission.cell_size_m > 0.0) ||
      !std::isfinite(admission.cell_size_m) || !std::isfinite(admission.xll_m) || !std::isfinite(admission.yll_m))
    throw InvalidArgument("admission: world grid " + std::to_string(admission.rows) + " x " +
                          std::to_string(admission.cols) + " with cell size " +
                          std::to_string(admission.cell_size_m) + " m is not a valid grid");
  return {admission.rows, admission.cols, admission.xll_m, admission.yll_m, admission.cell_size_m};
}

NavigabilityParams construction_params(const AgentContext& context) {
  const Task& t = context.task;
  return {t.construction_kappa.value_or(context.body.navigability.kappa), t.construction_width_m.value_or(context.body.navigability.delta_m),
          t.construction_eps_m.value_or(context.body.navigability.eps_m)};
}

double neighbour_keep_out_m(double max_delta_m, double max_step_m) { return 0.5 * max_delta_m + max_step_m + 1e-6; }

}  // namespace marsala::agent
