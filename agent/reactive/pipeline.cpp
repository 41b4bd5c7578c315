#include "marsala/agent/reactive/pipeline.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"

namespace marsala::agent::reactive {
namespace {

constexpr EnumName<PipelineRole> kPipelineRoleNames[] = {{PipelineRole::kActive, "active"},
                                                         {PipelineRole::kFollow, "follow"},
                                                         {PipelineRole::kHold, "hold"},
                                                         {PipelineRole::kBackOff, "back_off"}};

Position where(const Neighbour& n) { return n.position; }

}  // namespace

std::string to_string(PipelineRole role) { return enum_to_string(kPipelineRoleNames, role); }

PipelineTracker::PipelineTracker(PipelineParams params) : params_(params) {
  const auto finite = [](double v) { return std::isfinite(v); };
  if (!finite(params.separation_m) || !(params.separation_m > 0.0) || !finite(params.back_off_margin_m) ||
      !(params.back_off_margin_m >= 0.0) || !(params.back_off_margin_m < params.separation_m) ||
      !finite(params.return_detect_m) || !(params.return_detect_m > 0.0))
    throw InvalidArgument(fmt::format(
        "pipeline: separation ({} m) and return detection ({} m) must be finite and > 0, the back-off margin ({} m) in "
        "[0, separation)",
        params.separation_m, params.return_detect_m, params.back_off_margin_m));
}

void PipelineTracker::observe(const std::vector<Neighbour>& neighbours, Position target) {
  std::map<std::uint32_t, Track> next;
  for (const Neighbour& n : neighbours) {
    const double d = distance(where(n), target);
    Track track;
    const auto old = tracks_.find(n.agent_id);
    if (old == tracks_.end()) {
      track.extreme_m = d;
    } else {
      // Hysteresis both ways: `extreme` is the nearest distance to the target while approaching, the farthest while
      // returning; a move of return_detect_m against it flips the direction.
      track = old->second;
      if (!track.returning) {
        track.extreme_m = std::min(track.extreme_m, d);
        if (d - track.extreme_m >= params_.return_detect_m) track.returning = true, track.extreme_m = d;
      } else {
        track.extreme_m = std::max(track.extreme_m, d);
        if (track.extreme_m - d >= params_.return_detect_m) track.returning = false, track.extreme_m = d;
      }
    }
    track.last = n;
    next.emplace(n.agent_id, track);
  }
  tracks_ = std::move(next);
}

bool PipelineTracker::returning(std::uint32_t id) const {
  const auto it = tracks_.find(id);
  return it != tracks_.end() && it->second.returning;
}

std::optional<Neighbour> PipelineTracker::front(Position self, Position target) const {
  const double mine = distance(self, target);
  std::optional<Neighbour> best;
  double best_d = std::numeric_limits<double>::infinity();
  for (const auto& [id, track] : tracks_) {
    if (track.returning) continue;
    if (!(distance(where(track.last), target) < mine - kAheadMarginM)) continue;
    const double d = distance(where(track.last), self);
    if (d < best_d) best_d = d, best = track.last;  // map order: ties to the lower id
  }
  return best;
}

PipelinePlace PipelineTracker::place(Position self, Position target) const {
  PipelinePlace p;
  p.front = front(self, target);
  if (!p.front) return p;
  const double d = distance(where(*p.front), self);
  p.role = d > params_.separation_m                                ? PipelineRole::kFollow
           : d >= params_.separation_m - params_.back_off_margin_m ? PipelineRole::kHold
                                                                   : PipelineRole::kBackOff;
  return p;
}

}  // namespace marsala::agent::reactive
