#include "marsala/world_server/runtime/standing_answers.hpp"

#include <cstring>

namespace marsala::world_server {
namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// True when `frame` tells its agent nothing that `told` did not: no terrain, no scan, not run over, and the same pose,
/// material, last result and reason and neighbours (bit for bit).
bool nothing_new(const protocol::SensorFrame& frame, const protocol::SensorFrame& told) {
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

StandingAnswers::StandingAnswers(std::size_t slots, bool allowed) : allowed_(allowed), slots_(slots) {}

StandingAnswers::Slot* StandingAnswers::slot(std::uint32_t id) {
  return id >= 1 && id <= slots_.size() ? &slots_[id - 1] : nullptr;
}

const StandingAnswers::Slot* StandingAnswers::slot(std::uint32_t id) const {
  return id >= 1 && id <= slots_.size() ? &slots_[id - 1] : nullptr;
}

void StandingAnswers::told(const protocol::SensorFrame& frame) {
  Slot* s = slot(frame.agent_id);
  if (s == nullptr) return;
  s->standing.reset();
  protocol::SensorFrame kept;  // what nothing_new() compares: the frame without its terrain and scan
  kept.agent_id = frame.agent_id;
  kept.step = frame.step;
  kept.x_m = frame.x_m;
  kept.y_m = frame.y_m;
  kept.z_m = frame.z_m;
  kept.material_m3 = frame.material_m3;
  kept.last_result = frame.last_result;
  kept.last_reason = frame.last_reason;
  kept.neighbours = frame.neighbours;
  s->told = std::move(kept);
}

bool StandingAnswers::answered(std::uint32_t id, const protocol::ActionRequest& r) {
  Slot* s = slot(id);
  if (s == nullptr) return true;
  s->standing.reset();
  if (!r.standing || !allowed_) return true;
  if (!empty_request(r) || !s->told) return false;
  s->standing = r;
  return true;
}

std::optional<protocol::ActionRequest> StandingAnswers::stands_for(std::uint32_t id,
                                                                   const protocol::SensorFrame& frame) const {
  const Slot* s = slot(id);
  if (s == nullptr || !s->standing || !s->told || !nothing_new(frame, *s->told)) return std::nullopt;
  protocol::ActionRequest r = *s->standing;
  r.step = frame.step;
  r.decision_us = 0;  // no decision was made for this step
  r.decision_cpu_us = 0;
  return r;
}

void StandingAnswers::forget(std::uint32_t id) {
  if (Slot* s = slot(id)) *s = Slot{};
}

bool StandingAnswers::asked(std::uint32_t id) {
  Slot* s = slot(id);
  if (s == nullptr || !s->standing) return false;
  s->standing.reset();
  return true;
}

std::size_t StandingAnswers::standing() const {
  std::size_t n = 0;
  for (const Slot& s : slots_) n += s.standing ? 1 : 0;
  return n;
}

}  // namespace marsala::world_server
