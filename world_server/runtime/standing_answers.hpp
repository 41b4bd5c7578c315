#pragma once
// Standing answers (docs/runtime.md#standing-answers): an agent whose behaviour would answer every frame that tells it
// nothing new with the same empty request says so (ActionRequest::standing). Until a frame would tell it something new,
// the world writes it no frame and takes that answer, renewed for the step, as its request: an idle robot costs no
// datagram, no wake-up of its process and no wait of the world's. Pure: no bus, no clock; what the agent was told last
// is the frame its link holds (AgentLinks::last_frame()).
//
//   answered    its answer to a frame: standing when it says so, is empty and the scenario allows it
//   stands_for  the next frame tells nothing new against the one told last (no tile, no scan, the same pose,
//               material, result and neighbours, not run over): the standing answer for its step; otherwise the
//               frame goes out
//   end         a frame written (the agent answers it), a re-admission, a question: the answer no longer stands

#include <cstdint>
#include <optional>
#include <vector>

#include "marsala/protocol/messages.hpp"

namespace marsala::world_server {

/// True when `r` asks for nothing: no motion, no deposition or deposit, no refill.
bool empty_request(const protocol::ActionRequest& r);

/// Each agent's standing answer; see the header.
class StandingAnswers {
 public:
  /// For agents 1..`slots`; `allowed` false (the scenario's standing_answers: false): no answer ever stands.
  StandingAnswers(std::size_t slots, bool allowed);

  /// The agent's answer `r` to the frame of its step. It stands when it says so, is empty and standing is allowed;
  /// false when it says so but cannot stand (not empty): the world takes it for this step only.
  bool answered(std::uint32_t id, const protocol::ActionRequest& r);
  /// The standing answer of agent `id` for `frame` (its step's), when the agent has one and `frame` tells it nothing
  /// new against `told`, the frame written to it last (nullptr: none); nullopt otherwise (the frame must be written).
  std::optional<protocol::ActionRequest> stands_for(std::uint32_t id, const protocol::SensorFrame& frame,
                                                    const protocol::SensorFrame* told) const;
  /// Agent `id`'s answer no longer stands (a frame was written to it, it was admitted again). True when one stood.
  bool end(std::uint32_t id);

 private:
  bool allowed_;
  std::vector<std::optional<protocol::ActionRequest>> standing_;  // [agent id - 1]
};

}  // namespace marsala::world_server
