#include "marsala/agent/reactive/waiting_for.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace marsala::agent::reactive {
namespace {

std::string with_robots(std::string text, const std::string& close_by) {
  return close_by.empty() ? text : fmt::format("{}: robots {} close by", text, close_by);
}

}  // namespace

bool acts(const protocol::ActionRequest& request) {
  return request.move || request.refill || !request.depositions.empty() || !request.deposits.empty();
}

std::string robots_close_by(const std::vector<Neighbour>& neighbours, Position robot, double own_radius_m,
                            double gap_m) {
  std::vector<std::pair<double, std::uint32_t>> close;
  for (const Neighbour& n : neighbours) {
    const double d = distance(n.position, robot);
    if (d - n.radius_m - own_radius_m <= gap_m) close.emplace_back(d, n.agent_id);
  }
  std::sort(close.begin(), close.end());
  std::string text;
  for (const auto& [d, id] : close) text += fmt::format("{}{} at {:.1f} m", text.empty() ? "" : ", ", id, d);
  return text;
}

std::string front_neighbour_text(const Neighbour& front, Position robot, const std::string& why) {
  return fmt::format("front neighbour {} at {:.1f} m ({})", front.agent_id, distance(front.position, robot), why);
}

int ReturnProgress::observe(double distance_m) {
  if (best_m_ < 0.0 || distance_m < best_m_ - kMinGainM) {
    best_m_ = distance_m;
    frames_ = 0;
    return 0;
  }
  return ++frames_;
}

std::string return_waiting_text(const BuildTrace& trace, const protocol::ActionRequest& request,
                                const std::string& close_by, int no_nearer_frames, double distance_m) {
  if (acts(request)) {
    if (no_nearer_frames < kReturnPatienceFrames) return "";
    return with_robots(fmt::format("no nearer the base ({:.1f} m) for {} steps", distance_m, no_nearer_frames),
                       close_by);
  }
  if (!trace.planned) return with_robots("no way towards the base in the known map", close_by);
  if (!trace.plan.found) return with_robots("no route towards the base through known cells", close_by);
  return with_robots("no step towards the base", close_by);
}

std::string build_waiting_text(const std::string& close_by) {
  return with_robots("no deposition path through known cells", close_by);
}

}  // namespace marsala::agent::reactive
