#pragma once
// Reactive layer (paper Fig. 1): a behaviour turns each sensor frame into one action request. Behaviours are
// chosen by name from a registry filled by register_builtins(): "ramp_builder" builds a navigable ramp to its
// target (paper §IV, Fig. 2), "path_builder" does so inside the construction pipeline (paper §V-A, Fig. 4), "idle"
// requests nothing (the lockstep benchmark's agent).
//
// decide() is the pure core: it depends only on the agent's context, its admission and the frames so far (no
// clock, no unseeded randomness), so it is testable without DDS and a run is reproducible bit for bit.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "marsala/agent/agent_context.hpp"
#include "marsala/agent/deliberative/known_map.hpp"
#include "marsala/core/registry.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::agent::reactive {

/// One robot's behaviour state machine.
class Behaviour {
 public:
  virtual ~Behaviour() = default;
  /// The registry name of this behaviour.
  virtual std::string name() const = 0;
  /// The current state's name (sent in every request for the monitor).
  virtual std::string state_name() const = 0;
  /// The world admitted the agent: grid, start, target and base become known. Throws InvalidArgument when the
  /// admission is for another agent or session, or its grid is invalid.
  virtual void on_admission(const protocol::Admission& admission) = 0;
  /// The request for this frame (same step, this agent's id and session). Throws InvalidArgument before
  /// admission, for another agent's frame, or for a frame whose tiles do not fit the grid. On a run_over frame
  /// it returns an empty request and the behaviour is done.
  virtual protocol::ActionRequest decide(const protocol::SensorFrame& frame) = 0;
  /// What the last decision waits for, in a few words ("front neighbour 7 at 1.4 m (hold)"); "" when nothing holds it
  /// up. Sent in every request (ActionRequest::waiting_for) for the world's stall account.
  virtual std::string waiting_for() const { return ""; }
  /// True when the last decision's (empty) request is this behaviour's answer to every later frame that tells it nothing
  /// new (the same pose, material, last result and neighbours; no terrain, no scan): deciding such a frame would
  /// return the same request and leave the behaviour as it is. The runtime then says the answer stands
  /// (ActionRequest::standing) and the world writes no frame until one tells something new
  /// (docs/runtime.md#standing-answers). A behaviour that counts steps or draws randomness per frame must say false.
  virtual bool answer_stands() const { return false; }
  /// Where the robot believes the terrain of its next frames lies (executive::MappingSystem::set_registration);
  /// behaviours without a map ignore it.
  virtual void set_registration(CellIndex /*offset*/) {}
  /// The part of the robot's localisation error the whole-cell registration leaves out [m] (believed position = the
  /// frame's + this): its scans are inserted from the sensor origin it believes, so hits land displaced by the whole
  /// error (docs/runtime.md#localisation-error); behaviours without a scanned map ignore it.
  virtual void set_sub_cell_error(Position /*error_m*/) {}
  /// The robot's own map as it stands (executive::MappingSystem::known_map(), valid while this behaviour lives and
  /// decides nothing more); nullopt before admission and for behaviours that keep no map. Read-only: for outputs
  /// (marsala-agent --dump-map) and tests.
  virtual std::optional<deliberative::KnownMap> known_map() const { return std::nullopt; }
};

/// Behaviours by name; each is made from the agent's context (admission still empty).
using BehaviourRegistry = Registry<Behaviour, const AgentContext&>;

/// An empty registry whose messages speak of behaviours.
BehaviourRegistry make_behaviour_registry();
/// Registers the built-in behaviours: "idle", "ramp_builder", "path_builder".
void register_builtins(BehaviourRegistry& registry);
/// A built-in behaviour by name; throws InvalidArgument listing the valid names when unknown.
std::unique_ptr<Behaviour> make_behaviour(const std::string& name, const AgentContext& context);
/// The robot's behaviour: context.type.behaviour, acting on a noisy belief of its pose (noisy_localisation.hpp) when
/// its robot type has localisation noise; throws as make_behaviour.
std::unique_ptr<Behaviour> make_robot_behaviour(const AgentContext& context);

/// An empty request answering `frame`: the envelope filled, no motion, no deposition, no refill.
protocol::ActionRequest empty_request(const AgentContext& context, const protocol::SensorFrame& frame,
                                      const std::string& state);
/// The assignment an admission gives `context`'s agent; throws InvalidArgument when the admission is not for it (id,
/// session, refused) or its grid or tile size is not valid.
Assignment assignment_from(const AgentContext& context, const protocol::Admission& admission);
/// Checks that a frame belongs to this agent; throws InvalidArgument otherwise.
void check_frame(const AgentContext& context, const protocol::SensorFrame& frame);

}  // namespace marsala::agent::reactive
