#include "marsala/agent/reactive/idle_behaviour.hpp"

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala::agent::reactive {

void IdleBehaviour::on_admission(const protocol::Admission& admission) {
  context_.assignment = assignment_from(context_, admission);
  admitted_ = true;
}

protocol::ActionRequest IdleBehaviour::decide(const protocol::SensorFrame& frame) {
  if (!admitted_) throw InvalidArgument(fmt::format("idle behaviour: frame for step {} before admission", frame.step));
  check_frame(context_, frame);
  if (frame.run_over) done_ = true;
  return empty_request(context_, frame, state_name());
}

}  // namespace marsala::agent::reactive
