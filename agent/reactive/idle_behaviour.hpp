#pragma once
// "idle": answers every frame with an empty request. The lockstep benchmark's agent: it measures the runtime's
// round trip without any terrain work.

#include "marsala/agent/reactive/behaviour.hpp"

namespace marsala::agent::reactive {

/// Sends an empty request every step.
class IdleBehaviour final : public Behaviour {
 public:
  explicit IdleBehaviour(const AgentContext& context) : context_(context) {}
  std::string name() const override { return "idle"; }
  std::string state_name() const override { return done_ ? "done" : admitted_ ? "idle" : "wait_admission"; }
  void on_admission(const protocol::Admission& admission) override;
  protocol::ActionRequest decide(const protocol::SensorFrame& frame) override;

 private:
  AgentContext context_;
  bool admitted_ = false;
  bool done_ = false;
};

}  // namespace marsala::agent::reactive
