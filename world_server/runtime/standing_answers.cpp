#include "marsala/world_server/runtime/standing_answers.hpp"

namespace marsala::world_server {
namespace {

/// True when `frame` tells its agent nothing that `told` did not: no terrain, no scan, not run over, and the same pose,
/// material, last result and reason and neighbours (bit for bit).
bool nothing_new(const protocol::SensorFrame& frame, const protocol::SensorFrame& told) {
  using protocol::same_bits;
  if (frame.run_over || frame.scanned || !frame.tiles.empty() || !frame.points.empty()) return false;
  if (!same_bits(frame.x_m, told.x_m) || !same_bits(frame.y_m, told.y_m) || !same_bits(frame.z_m, told.z_m) ||
      !same_bits(frame.material_m3, told.material_m3) || frame.last_result != told.last_result ||
      frame.last_reason != told.last_reason || frame.neighbours.size() != told.neighbours.size())
    return false;
  for (std::size_t i = 0; i < frame.neighbours.size(); ++i) {
    const Neighbour &a = frame.neighbours[i], &b = told.neighbours[i];
    if (a.agent_id != b.agent_id || !same_bits(a.position.x, b.position.x) || !same_bits(a.position.y, b.position.y) ||
        !same_bits(a.z_m, b.z_m) || !same_bits(a.radius_m, b.radius_m))
      return false;
  }
  return true;
}

}  // namespace

bool empty_request(const protocol::ActionRequest& r) {
  return !r.move && r.depositions.empty() && r.deposits.empty() && !r.refill;
}

StandingAnswers::StandingAnswers(std::size_t slots, bool allowed) : allowed_(allowed), standing_(slots) {}

bool StandingAnswers::answered(std::uint32_t id, const protocol::ActionRequest& r) {
  end(id);
  if (!r.standing || !allowed_ || id < 1 || id > standing_.size()) return true;
  if (!empty_request(r)) return false;
  standing_[id - 1] = r;
  return true;
}

std::optional<protocol::ActionRequest> StandingAnswers::stands_for(std::uint32_t id, const protocol::SensorFrame& frame,
                                                                   const protocol::SensorFrame* told) const {
  if (id < 1 || id > standing_.size() || !standing_[id - 1] || told == nullptr || !nothing_new(frame, *told))
    return std::nullopt;
  protocol::ActionRequest r = *standing_[id - 1];
  r.step = frame.step;
  r.decision_us = 0;  // no decision was made for this step
  r.decision_cpu_us = 0;
  return r;
}

bool StandingAnswers::end(std::uint32_t id) {
  if (id < 1 || id > standing_.size() || !standing_[id - 1]) return false;
  standing_[id - 1].reset();
  return true;
}

}  // namespace marsala::world_server
