#pragma once
// The admission gate (docs/runtime.md#load-limits, #takeover): which hellos the world may act on and answer, pure and
// with the clock passed in. Agents repeat their hello every 200 ms until answered; a flood of one-shot random sessions
// never does. The gate remembers senders in bounded maps, so no flood can grow the world's memory.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>

#include "marsala/protocol/messages.hpp"

namespace marsala::world_server {

/// A participant's RTPS GUID prefix (bus::WriterId::prefix; this bus-free unit keeps the bytes).
using WriterPrefix = std::array<std::uint8_t, 12>;

/// Who says hello: an agent id, the session of its process and the participant that wrote it (a copy of another
/// agent's hello, read on the default partition, is another sender: docs/runtime.md#who-wrote-it).
struct SenderKey {
  std::uint32_t agent_id = 0;  ///< the hello's agent id (kAnySlot included)
  std::uint64_t session = 0;   ///< the hello's session: one per agent process
  WriterPrefix writer{};       ///< GUID prefix of the participant that wrote the hello (unknown: all zero)
  /// Ordered by agent id, then session, then writer.
  bool operator<(const SenderKey& o) const {
    if (agent_id != o.agent_id) return agent_id < o.agent_id;
    return session != o.session ? session < o.session : writer < o.writer;
  }
  /// Same id, session and writer.
  bool operator==(const SenderKey& o) const {
    return agent_id == o.agent_id && session == o.session && writer == o.writer;
  }
};

/// The sender of `hello`, written by the participant of GUID prefix `writer`.
inline SenderKey sender_of(const protocol::AgentHello& hello, const WriterPrefix& writer = {}) {
  return {hello.agent_id, hello.session, writer};
}

/// A session is admitted (first, re-admission, takeover) only on a hello repeated at least this long after its first.
inline constexpr std::chrono::milliseconds kHelloConfirmation{100};
/// Hellos are remembered for up to two generations of this long.
inline constexpr std::chrono::milliseconds kHelloMemory{1000};
/// A new session of a live agent whose old session is still connected waits this long before it is refused: the old
/// writer's liveliness lapses within the 1 s DDS lease when its process died [ms].
inline constexpr std::chrono::milliseconds kTakeoverWait{3000};
/// Each sender is answered at most this often; the legitimate agent says hello every 200 ms.
inline constexpr std::chrono::milliseconds kAnswerInterval{150};
/// Bounds of the per-sender bookkeeping: beyond them, hellos are counted, not remembered.
inline constexpr std::size_t kMaxAnswerKeys = 4096;
inline constexpr std::size_t kMaxRefusalKeys = 1024;
/// Refusals answered per round of hellos at most: a flood of hellos must not become a flood of admissions.
inline constexpr int kMaxRefusalAnswers = 16;

/// What the takeover wait says of a hello (AdmissionGate::takeover()).
enum class TakeoverWait {
  kNone,     ///< not waiting: the slot is not held by another connected session, or the wait is over
  kStarted,  ///< the wait for the old session to go starts now (the first persistent hello of the new session)
  kWaiting,  ///< still waiting (or the sender has said hello only once): not answered yet
};

/// The gate's memory of senders; every method takes the time of the round it serves.
class AdmissionGate {
 public:
  using Clock = std::chrono::steady_clock;  ///< the runtime's clock; the gate only compares its time points

  /// True when `sender` said hello before, at least kHelloConfirmation before `now` (within the last two
  /// generations of kHelloMemory); remembers this hello. Bounded: a generation holds the hellos of kHelloMemory.
  bool persistent(SenderKey sender, Clock::time_point now);

  /// The takeover wait of `sender`, a new session of a live slot: `held` says the slot's admitted session is another
  /// one and still connected. Not held: kNone. Held: kWaiting while the sender is not persistent() or for
  /// kTakeoverWait from its first persistent hello (kStarted that first time), then kNone (the decision refuses it).
  TakeoverWait takeover(SenderKey sender, bool held, Clock::time_point now);

  /// True when `sender` may be answered at `now`: each at most every kAnswerInterval (remembers the answer).
  bool may_answer(SenderKey sender, Clock::time_point now);

  /// Counts a refusal of `sender`; true when it is to be reported: the first of each sender while the memory of them
  /// lasts (kMaxRefusalKeys), then the 1st, 10th, 100th ... refusal overall.
  bool report_refusal(SenderKey sender);

  /// Starts a round of hellos: the refusals answered in it start at 0.
  void begin_round() { refusal_answers_ = 0; }
  /// Counts a refusal to be answered in this round; false beyond kMaxRefusalAnswers.
  bool may_answer_refusal() { return ++refusal_answers_ <= kMaxRefusalAnswers; }

  /// Refusals counted so far.
  std::uint64_t refusals() const { return refusals_; }
  /// Senders remembered in all maps (bounded by the constants above).
  std::size_t remembered() const;

 private:
  std::map<SenderKey, Clock::time_point> seen_current_, seen_previous_;  ///< first hello per sender (persistent())
  Clock::time_point seen_rotated_{};
  std::map<SenderKey, Clock::time_point> takeover_since_;  ///< first persistent hello of a waiting new session
  std::map<SenderKey, Clock::time_point> answered_at_;     ///< last answer per sender
  std::set<SenderKey> refused_;                            ///< senders already reported as refused
  std::uint64_t refusals_ = 0;
  int refusal_answers_ = 0;
};

}  // namespace marsala::world_server
