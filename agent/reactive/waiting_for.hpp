#pragma once
// What a building robot waits for, in a few words (ActionRequest::waiting_for, docs/runtime.md#stall): texts made
// from what one decision saw, so that a stalled run's account says why each robot stands still. Pure; for people.

#include <string>
#include <vector>

#include "marsala/agent/reactive/ramp_steps.hpp"
#include "marsala/core/types.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::agent::reactive {

/// True when `request` does something: a motion, a deposition or deposit, or a refill.
bool acts(const protocol::ActionRequest& request);

/// The neighbours whose bodies come within `gap_m` of the body (radius own_radius_m) at `robot`, nearest first, as
/// "3 at 1.2 m, 5 at 1.4 m" (centre distances, 0.1 m); "" when none does.
std::string robots_close_by(const std::vector<Neighbour>& neighbours, Position robot, double own_radius_m,
                            double gap_m);

/// A robot that waits on its front neighbour: "front neighbour 7 at 1.4 m (hold)", `why` in the brackets.
std::string front_neighbour_text(const Neighbour& front, Position robot, const std::string& why);

/// A robot on its way back: how long it has come no nearer the base. A robot that steps to and fro among others
/// moves in every step and still does not get back.
class ReturnProgress {
 public:
  /// Takes one frame of the return, the robot `distance_m` from the base [m]; returns the frames in a row, this one
  /// included, in which it came no nearer than its best of this return by at least kMinGainM (0: it did now).
  int observe(double distance_m);
  /// The return is over (the robot refilled): the next one starts afresh.
  void reset() { *this = ReturnProgress(); }
  /// Nearer by less than this is no nearer [m].
  static constexpr double kMinGainM = 0.05;

 private:
  double best_m_ = -1.0;  // < 0: no frame yet
  int frames_ = 0;
};

/// A returning robot waits this many frames without getting nearer the base before it says so.
inline constexpr int kReturnPatienceFrames = 40;

/// What a returning robot waits for after return_step(): when it asked for nothing, "no way towards the base in the
/// known map" (no cell to head for), "no route towards the base through known cells" (no plan) or "no step towards
/// the base" (a route, but no motion along it); when it moves but has come no nearer for at least
/// kReturnPatienceFrames frames, "no nearer the base (19.8 m) for 57 steps"; else "". Each but "" followed by
/// ": robots <robots_close_by> close by" when `close_by` is not empty.
std::string return_waiting_text(const BuildTrace& trace, const protocol::ActionRequest& request,
                                const std::string& close_by, int no_nearer_frames, double distance_m);

/// A build_step() that found no deposition path: "no deposition path through known cells", with the robots close by.
std::string build_waiting_text(const std::string& close_by);

}  // namespace marsala::agent::reactive
