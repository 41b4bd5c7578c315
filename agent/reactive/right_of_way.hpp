#pragma once
// Right of way among solid robots (docs/runtime.md#right-of-way: the rules and their invariant), from proximity
// sensing alone. Robots that stand still side by side may be waiting for each other (each one's way runs through the
// other's body); nothing outside them changes that, so one of them must give way, and all of them must agree which
// without talking:
//
//   - the lower agent id goes first; a robot at its goal has the lowest priority (it loses nothing by moving);
//   - a neighbour of lower id that is on its way (moved within kMovingFrames frames) has its lane ahead reserved
//     (lanes()): a robot keeps out of it and leaves it when it stands in it;
//   - a robot that has made no way for kStuckFrames frames (and did no work in place) with a neighbour in contact
//     holds still for kStillFrames + an episode, so that the neighbour sees it wait;
//   - a robot that has loitered kStillFrames frames gives way (steps away for an episode) to a neighbour in contact
//     that holds (has stood still kStillFrames to kStillFrames + an episode frames): to a lower id only, or, at its
//     goal, to any id, also to one that loiters beside it, for three episodes and once per spot where it waits;
//   - one that left a spot where it stood still longer than a hold and came back is parked there, not holding;
//   - neighbours keep their record out of range (one parked all along does not seem to start holding again).

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "marsala/core/robot_body.hpp"
#include "marsala/core/types.hpp"

namespace marsala::agent::reactive {

/// Frames a robot and a neighbour must both have loitered before one gives way.
inline constexpr int kStillFrames = 16;
/// Frames without progress (its distance to where it is going shrinking by a step) after which a robot with a
/// neighbour in contact holds still, so that the neighbour can see it waits.
inline constexpr int kStuckFrames = 24;
/// A neighbour that moved within this many frames is on its way: its lane ahead is reserved [frames].
inline constexpr int kMovingFrames = 3;
/// After giving way from its goal, a robot stands aside while the robot it gave way to still drives in contact, for
/// at most this many episodes [episodes].
inline constexpr int kAsideEpisodes = 4;

/// Robots of this body whose centres lie nearer than this are in contact: their bodies, a step each and a body of
/// slack (a robot that tries and backs off in turn is not always at its nearest) [m].
double give_way_contact_m(const RobotBody& body);
/// Frames of one giving-way episode: two body lengths of steps.
int give_way_frames(const RobotBody& body);

/// The way ahead of a moving robot with the right of way: the capsule of `radius_m` around the segment from `from`
/// to `to` [m]. A robot of a higher id keeps out of it, and leaves it when it stands in it.
struct Lane {
  Position from;
  Position to;
  double radius_m = 0.0;
  /// True when `p` [m] lies within radius_m of the segment.
  bool contains(Position p) const;
  /// The segment's box widened by radius_m and a margin that covers rounding [m]: no point beyond it is contained.
  Rect box() const;
};

/// True when `p` [m] lies in one of `lanes`.
bool in_any(const std::vector<Lane>& lanes, Position p);

/// Who gives way to whom among robots standing still in contact; see the header.
class RightOfWay {
 public:
  /// `self_id` this robot's id; contact_m [m] the largest centre distance of robots in contact; loiter_m [m] how far
  /// from where it stood a loitering robot stays; give_way_frames the length of an episode. Throws InvalidArgument
  /// unless contact_m and loiter_m are finite and > 0 and give_way_frames >= 1.
  RightOfWay(std::uint32_t self_id, double contact_m, double loiter_m, int give_way_frames);

  /// One frame: where this robot stands and its neighbours (the frame's), at_goal when it is done, how far it still
  /// has to go to where it is going [m] (`step_m` [m]: what counts as progress), and `worked` when its last request
  /// deposited or refilled (work in place is progress too: a builder is not waiting), and `new_goal` when where it
  /// goes is not where it went last frame (its progress is then measured afresh: a goal vector map's next arrow).
  void observe(Position self, const std::vector<Neighbour>& neighbours, bool at_goal, double to_go_m, double step_m,
               bool worked = false, bool new_goal = false);
  /// observe() with where the robot goes, `going` [m]: how far it has to go is its distance from there, and its
  /// progress is measured afresh when that moved by more than step_m since the last frame (a goal vector map's next
  /// arrow, the base on the way back).
  void observe_towards(Position self, const std::vector<Neighbour>& neighbours, bool at_goal, Position going,
                       double step_m, bool worked);
  /// True while the robot holds still (made no way with a neighbour in contact; see the header).
  bool holding() const { return hold_left_ > 0; }
  /// True while the robot stands aside after giving way from its goal (the robot it gave way to still drives in
  /// contact: it has not got past yet).
  bool standing_aside() const { return aside_left_ > 0; }
  /// Where the robot it gives way to stood when the episode began [m], while an episode lasts; else nullopt.
  std::optional<Position> giving_way() const { return frames_left_ > 0 ? from_ : std::nullopt; }
  /// Frames this robot has loitered [frames].
  int loitering_frames() const { return self_.frames; }
  /// The lanes of the neighbours of lower id that moved within kMovingFrames frames: `length_m` [m] ahead of each
  /// along its last motion, of radius its body's radius plus `clearance_m` (this robot's radius and a step) [m]. A robot at its goal keeps out of
  /// them too (it comes back once the other has passed).
  std::vector<Lane> lanes(double length_m, double clearance_m) const;

 private:
  /// Frames within radius of an anchor, the position where the count began.
  struct Loiter {
    Position anchor;
    int frames = -1;  ///< -1: no position yet
    void update(Position p, double radius_m);
  };
  struct Seen {
    Position at;
    int still = 0;
    Position heading{0.0, 0.0};  ///< unit vector of its last motion, (0, 0) before one
    double radius_m = 0.0;
    Loiter loiter;
    long long frame = 0;  ///< the frame it was last seen in
    std::optional<Position> parked_at;  ///< where it last stood still for longer than a hold
    bool left_parked = false;           ///< it has been farther than loiter_m from parked_at since
  };
  std::uint32_t self_id_;
  double contact_m_;
  double loiter_m_;
  int give_way_frames_;
  Loiter self_;
  std::map<std::uint32_t, Seen> seen_;  // every neighbour seen, as last seen
  long long frame_ = 0;                 // frames observed
  std::map<std::uint32_t, Position> given_to_;  // at the goal: where each robot stood when this one gave way to it
  std::optional<Position> from_;
  int frames_left_ = 0;
  double best_to_go_m_ = 0.0;
  int no_progress_ = 0;
  int hold_left_ = 0;
  bool given_at_goal_ = false;  // the episode under way was given from the robot's goal
  std::uint32_t giving_to_ = 0;  // the robot the last episode gave way to
  int aside_left_ = 0;           // frames it may still stand aside
  std::optional<Position> going_;  // where the robot went last frame (observe_towards())
  bool displaced_ = false;       // it gave way from its goal and is not back on it: the lowest priority still
  bool stand_aside(Position self);  // one frame of standing aside at `self` [m]; true while it lasts
};

}  // namespace marsala::agent::reactive
