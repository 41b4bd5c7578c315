#pragma once
// "idle": answers every frame with an empty request, which stands (docs/runtime.md#standing-answers). The lockstep
// benchmark's agent: it measures the runtime without any terrain work (with standing_answers: false in the scenario,
// its round trip every step).

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
  /// Its empty request answers every frame alike: it stands once admitted, until the run is over.
  bool answer_stands() const override { return admitted_ && !done_; }

 private:
  AgentContext context_;
  bool admitted_ = false;
  bool done_ = false;
};

}  // namespace marsala::agent::reactive
