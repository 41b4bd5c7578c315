#pragma once
// The world's links to its admitted agents: per slot, the endpoints of the admitted session on its partition
// (protocol::partition_for(run_id, id, session)): a SensorFrame writer and an ActionRequest reader, the liveliness
// of the agent's request writer (liveliness.hpp) and the frame of the current step with its resend rule
// (resend_policy.hpp). A session belongs to
// the participant whose hello was admitted (its owner): requests on its partition from any other participant are
// ignored and counted (docs/runtime.md#who-wrote-it); the session, readable by anyone, is worth nothing to them.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "marsala/bus/bus.hpp"
#include "marsala/protocol/messages.hpp"
#include "marsala/world_server/rules/world_state.hpp"
#include "marsala/world_server/runtime/liveliness.hpp"
#include "marsala/world_server/runtime/resend_policy.hpp"

namespace marsala::world_server {

/// The endpoints of one admitted agent (process): its session's partition.
struct AgentLink {
  std::uint64_t session = 0;  ///< the session whose partition the endpoints use
  std::unique_ptr<bus::Writer<protocol::SensorFrame>> frames;
  std::unique_ptr<bus::Reader<protocol::ActionRequest>> requests;
  LivelinessWatch liveliness;                  ///< of its request writer
  std::optional<protocol::SensorFrame> frame;  ///< the current step's frame, for resends
  ResendPolicy resends;                        ///< when its frame is written again
  bus::WriterId owner;                         ///< the participant the session belongs to; unknown until bound
  bool accepted_here = false;  ///< this world process answered the session with an acceptance: the agent takes its frames
  std::uint64_t foreign = 0;                   ///< requests from other participants ignored [count]
};

/// Writes a sample; a failing write is logged, never fatal: one agent's broken link must not stop the world.
template <typename T>
void write_logged(bus::Writer<T>& writer, const T& sample, const char* what);

/// Links of slots 1..slots; a slot has endpoints once open() was called for it.
class AgentLinks {
 public:
  /// `signal` wakes the world when a request arrives on any link.
  AgentLinks(bus::Participant& participant, std::shared_ptr<bus::Signal> signal, std::string run_id, std::size_t slots);

  /// Opens the partition endpoints of `agent`'s admitted session, owned by participant `owner` (unknown: bound at
  /// the session's next hello, bind()), replacing another session's (a new link: its liveliness starts unseen);
  /// nothing when they are open already.
  void open(const AgentRecord& agent, const bus::WriterId& owner = {});
  /// Whether a hello of slot `id`'s admitted session written by `from` is its owner's: true when it is, or when the
  /// link has no owner yet (a resumed world), which `from` then becomes; false (counted, logged at the 1st, 10th,
  /// 100th ...) for another participant.
  bool bind(std::uint32_t id, const bus::WriterId& from);
  /// Requests and hellos of slot `id`'s session from participants other than its owner, ignored so far [count].
  std::uint64_t foreign(std::uint32_t id) const { return links_[id - 1].foreign; }
  /// True when slot `id` has endpoints.
  bool has(std::uint32_t id) const { return static_cast<bool>(links_[id - 1].requests); }
  /// True when the request writer of slot `id`'s session is alive (false without endpoints).
  bool connected(std::uint32_t id) const;
  /// True when slot `id`'s frame writer has matched a reader and its request writer is alive.
  bool ready(std::uint32_t id) const;
  /// True when no request writer of slot `id` is alive any more.
  bool gone(std::uint32_t id) const { return links_[id - 1].requests->alive_writers() == 0; }
  /// Observes slot `id`'s request writer at `now` (liveliness.hpp).
  LivelinessVerdict observe(std::uint32_t id, LivelinessWatch::Clock::time_point now);
  /// Forgets a running liveliness grace of slot `id` (it was just admitted again).
  void forgive(std::uint32_t id) { links_[id - 1].liveliness.forgive(); }
  /// Takes the requests received on slot `id`'s partition from its session's owner (none without endpoints); the
  /// others are counted as foreign.
  std::vector<protocol::ActionRequest> take(std::uint32_t id);
  /// Sends `frame` to slot `id` and keeps it for resend().
  void send(std::uint32_t id, protocol::SensorFrame frame);
  /// Sends slot `id` its kept frame again at `now` when the resend rule says so (resend_policy.hpp); false when it
  /// has no frame of `step`.
  bool resend(std::uint32_t id, std::uint64_t step, ResendPolicy::Clock::time_point now);
  /// True when a copy of slot `id`'s frames is on its way: a matched reader has not acknowledged it yet.
  bool in_flight(std::uint32_t id) const;
  /// Slot `id`'s agent said hello again (ResendPolicy::asked()): its unanswered frame is written once more at the
  /// next look unless a copy is in flight.
  void asked(std::uint32_t id) { links_[id - 1].resends.asked(); }
  /// This world process answered `session` of slot `id` with an acceptance (nothing for another session's link).
  void accepted(std::uint32_t id, std::uint64_t session) {
    AgentLink& link = links_[id - 1];
    if (link.requests && link.session == session) link.accepted_here = true;
  }
  /// True when answer_with_frame() can answer slot `id`'s agent: its link holds a frame it sent, and this process
  /// answered the session with an acceptance (after a resume the agent takes the new world's frames only then).
  bool answers_with_frame(std::uint32_t id) const {
    const AgentLink& link = links_[id - 1];
    return link.accepted_here && link.frame && link.frames;
  }
  /// Answers slot `id`'s agent, which asked whether it is still counted in, on its own partition: its latest frame
  /// again at `now` (answered or not), unless a copy is in flight, which answers it when it arrives. Needs
  /// answers_with_frame(); otherwise an admission answers (docs/runtime.md#re-admission).
  void answer_with_frame(std::uint32_t id, ResendPolicy::Clock::time_point now);
  /// The frame last written to slot `id`'s agent (what it was told), nullptr when none (no link, or none yet).
  const protocol::SensorFrame* last_frame(std::uint32_t id) const {
    const AgentLink& link = links_[id - 1];
    return link.frame ? &*link.frame : nullptr;
  }
  /// Copies of slot `id`'s current frame written besides the first [count].
  std::uint32_t resends(std::uint32_t id) const { return links_[id - 1].resends.resends(); }

 private:
  bus::Participant& participant_;
  std::shared_ptr<bus::Signal> signal_;
  std::string run_id_;
  /// Counts one sample of slot `id`'s session from `from`, not its owner, and logs the 1st, 10th, 100th ...
  void count_foreign(std::uint32_t id, const bus::WriterId& from, const char* what);

  std::vector<AgentLink> links_;  ///< [id - 1]
};

}  // namespace marsala::world_server
