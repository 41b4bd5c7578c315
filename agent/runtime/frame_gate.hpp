#pragma once
// The frame gate: which sensor frame the agent takes during the lockstep, and what it does with it
// (docs/runtime.md#lockstep). Pure: no bus traffic, no clock.
//
//   not from the world it was admitted to, not addressed to it, too far ahead, or not sane -> ignored (the problem)
//   run_over                                                                                -> the run is over
//   the step last answered (the world did not get the answer)                               -> the same request again
//   an earlier step, from the world that had sent the frames answered (a late copy)          -> stale
//   an earlier step, from a world restarted since (a resume that cut its log's damaged tail,
//   docs/runtime.md#resume): the requests kept                                              -> the same request again
//   otherwise (a new step, or one older than the requests kept)                             -> decide, then answered()

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>

#include "marsala/bus/bus.hpp"
#include "marsala/core/assignment.hpp"
#include "marsala/core/sensor_spec.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::agent::runtime {

/// A frame further ahead of the last step answered is not the world's: no run goes on for a million steps while an
/// agent waits for its next frame [steps], unless the agent's last request stood (docs/runtime.md#standing-answers).
inline constexpr std::uint64_t kMaxStepsAhead = 1000000;
/// How many of its last requests an agent keeps, to repeat them when the world goes back to their steps [steps]: a
/// world resumed from a log whose damaged tail was cut replays those steps with the same requests, so the run ends as
/// it would have (a few MB at most).
inline constexpr std::size_t kRequestHistory = 20000;

/// Empty when a frame addressed to this agent can be trusted to describe the world of `assignment`: a finite pose on
/// the grid, finite height and material, tiles that fit the grid, a scan only for a scanning sensor with points within
/// its reach, finite neighbours; otherwise the problem. A frame with a problem is ignored whole, before any of it
/// reaches the behaviour (which would throw half-way through).
std::string frame_problem(const protocol::SensorFrame& frame, const Assignment& assignment, const SensorSpec& sensor);

/// What the gate makes of one frame.
enum class FrameCall {
  kIgnored,  ///< not this run's, or not sane: the problem says why
  kRunOver,  ///< the run is over
  kRepeat,   ///< the frame of a step already answered: send request_for(step) again, never a second decision
  kStale,    ///< a late copy of an earlier step's frame from the world that sent the frames answered
  kDecide,   ///< a new step (or one older than the requests kept): decide, send, then answered()
};

/// A frame's call and, when ignored, why.
struct FrameJudgement {
  FrameCall call = FrameCall::kIgnored;
  std::string problem;  ///< kIgnored: why, for the operator
};

/// Judges the frames of one admitted agent; see the header.
class FrameGate {
 public:
  /// Frames for agent `agent_id` of `assignment`, sensing with `sensor`, written by `world` (the participant whose
  /// admission let the agent in).
  FrameGate(std::uint32_t agent_id, Assignment assignment, SensorSpec sensor, bus::WriterId world);

  /// What to do with `frame`, written by participant `from`.
  FrameJudgement judge(const protocol::SensorFrame& frame, const bus::WriterId& from) const;
  /// The world now speaks from participant `world` (restarted from its log, docs/runtime.md#resume).
  void set_world(const bus::WriterId& world) { world_ = world; }
  /// The participant frames are taken from.
  const bus::WriterId& world() const { return world_; }
  /// The request sent for the frame of `step`, repeated when that frame comes again; forgets the requests of `step`
  /// and later ones (a world that went back decides again from there) and the oldest beyond kRequestHistory.
  void answered(std::uint64_t step, protocol::ActionRequest request);
  /// The request sent for the frame of `step`, when it is kept: the one answering `step`, or a standing one sent for
  /// an earlier step and not followed by another before `step` (the world held its frames back), for `step`;
  /// nullopt otherwise.
  std::optional<protocol::ActionRequest> request_for(std::uint64_t step) const;

 private:
  std::uint32_t agent_id_;
  Assignment assignment_;
  SensorSpec sensor_;
  bus::WriterId world_;
  bool answered_any_ = false;
  std::uint64_t last_answered_ = 0;                                     // the step of the last request sent
  bus::WriterId answered_world_;                                        // the world whose frame was last answered
  std::deque<std::pair<std::uint64_t, protocol::ActionRequest>> sent_;  // (step, request), ascending steps
};

}  // namespace marsala::agent::runtime
