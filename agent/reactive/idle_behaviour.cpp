#include "marsala/agent/reactive/idle_behaviour.hpp"

#include "marsala/core/error.hpp"

namespace marsala::agent::reactive {

void IdleBehaviour::on_admission(const protocol::Admission& admission) {
  context_.assignment = assignment_from(context_, admission);
  admitted_ = true;
}

protocol::ActionRequest IdleBehaviour::decide(const protocol::SensorFrame& frame) {
  if (!admitted_)
    throw InvalidArgument("idle behaviour: frame for step " + std::to_string(frame.step) + " before admission");
  check_frame(context_, frame);
  if (frame.run_over) done_ = true;
  return empty_request(context_, frame, state_name());
}

}  // namespace marsala::agent::reactive
