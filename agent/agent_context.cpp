#include "marsala/agent/agent_context.hpp"

#include <cmath>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::agent {

double neighbour_keep_out_m(double max_delta_m, double max_step_m) { return 0.5 * max_delta_m + max_step_m + 1e-6; }

}  // namespace marsala::agent
