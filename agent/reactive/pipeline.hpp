#pragma once
// The construction pipeline (paper §V-A, Fig. 4), seen by one robot through its proximity sensing alone.
//
// Robots form a pipeline from the base station towards the target. A neighbour is *ahead* when it stands nearer the
// target (straight-line distance) by more than kAheadMarginM, and *returning* once it has moved away from the target
// by at least return_detect_m since it was nearest to it (it is heading back to the base along the other lane; a
// short retreat of the active robot while it builds does not count); it counts as approaching again once it has come
// return_detect_m nearer than it was when farthest (it refilled and rejoined the pipeline). The *front neighbour* is
// the nearest (to this robot) neighbour that is ahead and not returning. The robot's role follows:
//
//   no front neighbour                                  -> kActive  (the front of the pipeline: it alone deposits)
//   front neighbour farther than separation_m           -> kFollow  (advance towards the target, never deposit)
//   front neighbour within [separation_m - back_off_margin_m, separation_m]
//                                                       -> kHold    (stand still)
//   front neighbour nearer than separation_m - back_off_margin_m
//                                                       -> kBackOff (step back towards the base)
//
// A neighbour out of proximity range is forgotten; when it is seen again it starts fresh (not returning).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "marsala/core/types.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::agent::reactive {

/// What a robot does in the pipeline this step.
enum class PipelineRole : std::uint8_t { kActive = 0, kFollow = 1, kHold = 2, kBackOff = 3 };
/// "active", "follow", "hold", "back_off".
std::string to_string(PipelineRole role);

/// A robot's place in the pipeline: its role and the front neighbour that decided it (none when kActive).
struct PipelinePlace {
  PipelineRole role = PipelineRole::kActive;
  std::optional<Neighbour> front;
};

/// Distances of the pipeline rule.
struct PipelineParams {
  double separation_m = 2.0;       ///< a follower keeps at least this far from its front neighbour [m]
  double back_off_margin_m = 0.5;  ///< it steps back only when nearer than separation - this [m]
  double return_detect_m = 1.5;    ///< a neighbour that moved this far away from the target is returning [m]
};

/// A neighbour ahead by less than this is level with the robot, not ahead [m].
inline constexpr double kAheadMarginM = 0.05;

/// Tracks neighbours across frames and decides the robot's role.
class PipelineTracker {
 public:
  /// Throws InvalidArgument unless separation > 0, 0 <= back_off_margin < separation and return_detect > 0, all
  /// finite.
  explicit PipelineTracker(PipelineParams params);
  const PipelineParams& params() const { return params_; }

  /// Takes one frame's neighbours (robots within proximity range), with `target` [m] the pipeline's target.
  void observe(const std::vector<Neighbour>& neighbours, Position target);
  /// True when neighbour `id` is currently seen and counted as returning.
  bool returning(std::uint32_t id) const;
  /// The front neighbour of a robot at `self` [m] (see the header), from the last observed frame.
  std::optional<Neighbour> front(Position self, Position target) const;
  /// The role of a robot at `self` [m] and its front neighbour, from the last observed frame.
  PipelinePlace place(Position self, Position target) const;

 private:
  struct Track {
    Neighbour last;
    double extreme_m = 0.0;  ///< nearest distance to the target while approaching, farthest while returning [m]
    bool returning = false;
  };
  PipelineParams params_;
  std::map<std::uint32_t, Track> tracks_;  // neighbours of the last frame only
};

}  // namespace marsala::agent::reactive
