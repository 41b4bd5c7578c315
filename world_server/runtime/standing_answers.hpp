#pragma once
// Standing answers (docs/runtime.md#standing-answers): an agent whose behaviour would answer every frame that tells it
// nothing new with the same empty request says so (ActionRequest::standing). Until a frame would tell it something new,
// the world writes it no frame and takes that answer, renewed for the step, as its request: an idle robot costs no
// datagram, no wake-up of its process and no wait of the world's. Pure: no bus, no clock.
//
//   told        the frame the agent was last written (pose, material, last result and reason, neighbours)
//   answered    its answer to that frame: standing when it says so, is empty and the scenario allows it
//   stands_for  the next frame tells nothing new against the one told (no tile, no scan, the same pose, material,
//               result and neighbours, not run over): the standing answer for its step; otherwise the frame goes out,
//               and told() ends the standing

#include <cstdint>
#include <optional>
#include <vector>

#include "marsala/protocol/messages.hpp"

namespace marsala::world_server {

/// True when `r` asks for nothing: no motion, no deposition or deposit, no refill.
bool empty_request(const protocol::ActionRequest& r);

/// Each agent's standing answer and the frame it was last told; see the header.
class StandingAnswers {
 public:
  /// For agents 1..`slots`; `allowed` false (the scenario's standing_answers: false): no answer ever stands.
  StandingAnswers(std::size_t slots, bool allowed);

  /// Frame `frame` was written to its agent: what the agent knows now; a standing answer ends (the agent answers it).
  void told(const protocol::SensorFrame& frame);
  /// The agent's answer `r` to the frame of its step. It stands when it says so, is empty and standing is allowed;
  /// false when it says so but cannot stand (not empty): the world takes it for this step only.
  bool answered(std::uint32_t id, const protocol::ActionRequest& r);
  /// The standing answer of agent `id` for `frame` (its step's), when the agent has one and `frame` tells it nothing
  /// new against the frame told last; nullopt otherwise (the frame must be written).
  std::optional<protocol::ActionRequest> stands_for(std::uint32_t id, const protocol::SensorFrame& frame) const;
  /// Agent `id` starts afresh (admitted again, dropped): no answer stands, nothing was told.
  void forget(std::uint32_t id);
  /// Agent `id` asked whether it is still counted in: its answer no longer stands, so its next frame goes out and
  /// answers it. True when an answer stood.
  bool asked(std::uint32_t id);
  /// How many agents hold a standing answer now [count].
  std::size_t standing() const;

 private:
  struct Slot {
    std::optional<protocol::SensorFrame> told;        // the last frame written, tiles and scan left out
    std::optional<protocol::ActionRequest> standing;  // the answer that stands
  };
  Slot* slot(std::uint32_t id);
  const Slot* slot(std::uint32_t id) const;

  bool allowed_;
  std::vector<Slot> slots_;  // [agent id - 1]
};

}  // namespace marsala::world_server
