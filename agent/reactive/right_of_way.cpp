#include "marsala/agent/reactive/right_of_way.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "marsala/core/error.hpp"

namespace marsala::agent::reactive {
namespace {

// Positions carry rounding of a few 1e-10 m (sums of steps): robots exactly contact_m apart are in contact.
constexpr double kContactTieM = 1e-6;

}  // namespace

double give_way_contact_m(const RobotBody& body) {
  return 2.0 * body.navigability.delta_m + 2.0 * body.max_step_m;
}

int give_way_frames(const RobotBody& body) {
  return static_cast<int>(std::ceil(2.0 * body.navigability.delta_m / body.max_step_m));
}

RightOfWay::RightOfWay(std::uint32_t self_id, double contact_m, double loiter_m, int give_way_frames)
    : self_id_(self_id), contact_m_(contact_m + kContactTieM), loiter_m_(loiter_m), give_way_frames_(give_way_frames) {
  if (!(contact_m > 0.0) || !std::isfinite(contact_m) || !(loiter_m > 0.0) || !std::isfinite(loiter_m) ||
      give_way_frames < 1)
    throw InvalidArgument(fmt::format(
        "right of way: contact range {} m and loitering radius {} m must be finite and > 0, episodes ({} frames) >= 1",
        contact_m, loiter_m, give_way_frames));
}

void RightOfWay::Loiter::update(Position p, double radius_m) {
  if (frames >= 0 && std::hypot(p.x - anchor.x, p.y - anchor.y) <= radius_m) {
    ++frames;
  } else {
    anchor = p, frames = 0;
  }
}

void RightOfWay::observe(Position self, const std::vector<Neighbour>& neighbours, bool at_goal, double to_go_m,
                         double step_m, bool worked, bool new_goal) {
  self_.update(self, loiter_m_);
  if (at_goal) displaced_ = false;
  // Frames spent holding or giving way are the protocol's, not tries: they neither count as no progress nor keep a
  // best distance from before them (a robot that stepped away from its goal, or held, gets kStuckFrames frames to
  // make way from where it stands before it holds again; else it held again at once, for ever).
  // A new goal starts its own count: the best distance to the old one says nothing of the way to it.
  const bool protocol_frame = hold_left_ > 0 || frames_left_ > 0 || aside_left_ > 0;
  if (at_goal || worked || protocol_frame || new_goal || to_go_m < best_to_go_m_ - step_m || no_progress_ < 0) {
    best_to_go_m_ = to_go_m, no_progress_ = 0;
  } else {
    ++no_progress_;
  }
  if (hold_left_ > 0) --hold_left_;
  ++frame_;
  // A neighbour keeps its record while out of range: one that comes back where it stood has stood still all along
  // (a robot parked at its goal does not start to "hold" again each time another comes back into range).
  for (const Neighbour& n : neighbours) {
    const auto old = seen_.find(n.agent_id);
    Seen s{n.position, 0, {0.0, 0.0}, n.radius_m, {}, frame_, std::nullopt, false};
    if (old != seen_.end()) {
      const double dx = n.position.x - old->second.at.x, dy = n.position.y - old->second.at.y;
      const double moved = std::hypot(dx, dy);
      s.still = moved == 0.0 ? old->second.still + (frame_ - old->second.frame) : 0;
      s.heading = moved > 0.0 ? Position{dx / moved, dy / moved} : old->second.heading;
      s.loiter = old->second.loiter;
      s.parked_at = old->second.parked_at;
      s.left_parked = old->second.left_parked;
    }
    if (s.still > kStillFrames + give_way_frames_) s.parked_at = s.at, s.left_parked = false;
    if (s.parked_at && std::hypot(s.at.x - s.parked_at->x, s.at.y - s.parked_at->y) > loiter_m_) s.left_parked = true;
    s.loiter.update(n.position, loiter_m_);
    seen_[n.agent_id] = s;
  }
  const bool contact = std::any_of(seen_.begin(), seen_.end(), [&](const auto& kv) {
    return kv.second.frame == frame_ && std::hypot(kv.second.at.x - self.x, kv.second.at.y - self.y) <= contact_m_;
  });
  if (no_progress_ >= kStuckFrames && contact && hold_left_ == 0 && frames_left_ == 0) {
    hold_left_ = kStillFrames + give_way_frames_;
    no_progress_ = 0, best_to_go_m_ = to_go_m;
  }
  if (stand_aside(self)) return;
  // Off its goal only to give way: it keeps the lowest priority until it is back (see lanes() and below); it still
  // holds when it makes no way back (above), so that a robot parked on its way gives way to it.
  at_goal = at_goal || displaced_;
  if (frames_left_ > 0 && --frames_left_ > 0) return;
  if (from_ && given_at_goal_) aside_left_ = kAsideEpisodes * give_way_frames_;  // the episode ends: stay aside
  from_.reset();
  if (stand_aside(self)) return;
  if (self_.frames < kStillFrames) return;
  // In contact: this robot has loitered long enough, the other holds still (it has stood still at least kStillFrames
  // and no longer than a hold: a robot parked at its goal waits for nobody), near enough. The lowest id goes first; a
  // robot at its goal gives way to anyone, and for longer (the other must get past before it comes back). Of several to give way to,
  // the nearest (ties: the lower id, map order).
  double nearest = contact_m_;
  std::uint32_t to_id = 0;
  for (const auto& [id, s] : seen_) {
    // Waits: holds still (at least kStillFrames and no longer than a hold: a robot parked at its goal waits for
    // nobody); to a robot at its goal, also one that has loitered that long (it tries and backs off in turn).
    // One that left where it stood still for longer than a hold and came back is parked there (back at its goal after
    // giving way): standing still there again is not a hold.
    const bool back_parked = s.left_parked && std::hypot(s.at.x - s.parked_at->x, s.at.y - s.parked_at->y) <=
                                                  loiter_m_ / 3.0;
    const bool holds = s.still >= kStillFrames && s.still <= kStillFrames + give_way_frames_ && !back_parked;
    const bool waits = holds || (at_goal && s.loiter.frames >= kStillFrames);
    if (s.frame != frame_ || !waits || (!at_goal && id > self_id_) || id == self_id_) continue;
    // At its goal a robot gives way to one that loiters beside it once where it loiters: one that loiters there
    // again after the episode waits for something else (it is parked at its own goal, or this robot is not what
    // blocks it). One that holds is given way to every time it holds: a hold is the signal of a robot that tried and
    // made no way (parked robots never hold), and where it holds again it has still not got past.
    const auto given = given_to_.find(id);
    if (at_goal && !holds && given != given_to_.end() &&
        std::hypot(s.at.x - given->second.x, s.at.y - given->second.y) <= loiter_m_ / 3.0)
      continue;
    const double d = std::hypot(s.at.x - self.x, s.at.y - self.y);
    if (d <= nearest) nearest = d, from_ = s.at, to_id = id;
  }
  if (!from_) return;
  if (at_goal) given_to_[to_id] = *from_;
  given_at_goal_ = at_goal, giving_to_ = to_id;
  displaced_ = displaced_ || at_goal;
  frames_left_ = (at_goal ? 3 : 1) * give_way_frames_;
  self_ = Loiter{};
  hold_left_ = 0;
}

void RightOfWay::observe_towards(Position self, const std::vector<Neighbour>& neighbours, bool at_goal, Position going,
                                 double step_m, bool worked) {
  const bool new_goal = going_ && std::hypot(going.x - going_->x, going.y - going_->y) > step_m;
  going_ = going;
  observe(self, neighbours, at_goal, std::hypot(going.x - self.x, going.y - self.y), step_m, worked, new_goal);
}

bool RightOfWay::stand_aside(Position self) {
  if (aside_left_ == 0) return false;
  // The robot it gave way to still drives in contact: it has not got past yet; coming back now cuts its way again.
  const auto other = seen_.find(giving_to_);
  const bool passing = other != seen_.end() && other->second.frame == frame_ &&
                       other->second.still < kMovingFrames &&
                       std::hypot(other->second.at.x - self.x, other->second.at.y - self.y) <=
                           contact_m_ + loiter_m_;
  aside_left_ = passing ? aside_left_ - 1 : 0;
  return aside_left_ > 0;
}

bool in_any(const std::vector<Lane>& lanes, Position p) {
  return std::any_of(lanes.begin(), lanes.end(), [&](const Lane& lane) { return lane.contains(p); });
}

Rect Lane::box() const {
  // The nearest point of the segment lies in its box, to within a rounding the margin covers.
  constexpr double kMarginM = 1e-6;
  const double reach_m = radius_m + kMarginM;
  Rect b;
  b.x0 = std::min(from.x, to.x) - reach_m;
  b.x1 = std::max(from.x, to.x) + reach_m;
  b.y0 = std::min(from.y, to.y) - reach_m;
  b.y1 = std::max(from.y, to.y) + reach_m;
  return b;
}

bool Lane::contains(Position p) const {
  // Most cells of a window lie beyond box() and skip the projection; callers that look for the cells of a lane visit
  // that box only (RampSteps::keep_out_of()).
  const Rect b = box();
  if (p.x < b.x0 || p.x > b.x1 || p.y < b.y0 || p.y > b.y1) return false;
  const double dx = to.x - from.x, dy = to.y - from.y, l2 = dx * dx + dy * dy;
  const double t = l2 > 0.0 ? std::clamp(((p.x - from.x) * dx + (p.y - from.y) * dy) / l2, 0.0, 1.0) : 0.0;
  return within(p.x - (from.x + t * dx), p.y - (from.y + t * dy), radius_m);
}

std::vector<Lane> RightOfWay::lanes(double length_m, double clearance_m) const {
  std::vector<Lane> out;
  for (const auto& [id, s] : seen_) {
    if (s.frame != frame_ || (id >= self_id_ && !displaced_) || s.still >= kMovingFrames || (s.heading.x == 0.0 && s.heading.y == 0.0)) continue;
    out.push_back({s.at, {s.at.x + length_m * s.heading.x, s.at.y + length_m * s.heading.y}, s.radius_m + clearance_m});
  }
  return out;
}

}  // namespace marsala::agent::reactive
