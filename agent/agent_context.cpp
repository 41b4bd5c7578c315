#include "agent/agent_context.hpp"

#include <cmath>
#include <string>

#include "common/error.hpp"

namespace marsala::agent {

NavigabilityParams navigability_params(const bus::BodyParams& body) {
  return {body.kappa, body.delta_m, body.eps_m};
}

grid::GridGeometry world_geometry(const bus::Admission& admission) {
  if (admission.rows <= 0 || admission.cols <= 0 || !(admission.cell_size_m > 0.0) ||
      !std::isfinite(admission.cell_size_m) || !std::isfinite(admission.xll_m) || !std::isfinite(admission.yll_m))
    throw InvalidArgument("admission: world grid " + std::to_string(admission.rows) + " x " +
                          std::to_string(admission.cols) + " with cell size " +
                          std::to_string(admission.cell_size_m) + " m is not a valid grid");
  return {admission.rows, admission.cols, admission.xll_m, admission.yll_m, admission.cell_size_m};
}

NavigabilityParams construction_params(const AgentContext& context) {
  const Task& t = context.task;
  return {t.construction_kappa.value_or(context.body.kappa), t.construction_width_m.value_or(context.body.delta_m),
          t.construction_eps_m.value_or(context.body.eps_m)};
}

double neighbour_keep_out_m(double max_delta_m, double max_step_m) { return 0.5 * max_delta_m + max_step_m + 1e-6; }

double cube_layer_m(const bus::BodyParams& body, double cell_size_m) {
  if (!(body.cube_size_m > 0.0) || !std::isfinite(body.cube_size_m) || !(cell_size_m > 0.0) ||
      !std::isfinite(cell_size_m))
    throw InvalidArgument("cube size " + std::to_string(body.cube_size_m) + " m and cell size " +
                          std::to_string(cell_size_m) + " m must be finite and > 0");
  return body.cube_size_m * body.cube_size_m * body.cube_size_m / (cell_size_m * cell_size_m);
}

}  // namespace marsala::agent
