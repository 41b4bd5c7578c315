#include "marsala/agent/runtime/frame_gate.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>

#include "marsala/agent/executive/mapping_system.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/robot_body.hpp"

namespace marsala::agent::runtime {

std::string frame_problem(const protocol::SensorFrame& f, const Assignment& assignment, const SensorSpec& sensor) {
  const auto sane = [](double v) { return std::isfinite(v) && std::abs(v) < kMaxMagnitude; };
  const Position pose{f.x_m, f.y_m};
  if (!sane(f.x_m) || !sane(f.y_m) || !assignment.world.cell_at(pose))
    return fmt::format("pose {} is not on the grid", pose);
  if (!sane(f.z_m) || !sane(f.material_m3) || f.material_m3 < 0.0)
    return fmt::format("height {} m or material {} m^3 is not a finite amount", f.z_m, f.material_m3);
  for (const TerrainTile& tile : f.tiles) {
    const std::string problem = executive::tile_problem(tile, assignment.world, assignment.tile_size);
    if (!problem.empty()) return problem;
  }
  if (!f.scanned && !f.points.empty()) return fmt::format("{} scan points in a frame without a scan", f.points.size());
  if (f.scanned && !sensor.casts_rays())
    return fmt::format("a scan for a robot whose sensor is '{}'", to_string(sensor.kind));
  const std::string scan = executive::scan_problem(f.points, sensor);
  if (!scan.empty()) return scan;
  for (const Neighbour& n : f.neighbours) {
    if (!sane(n.position.x) || !sane(n.position.y) || !sane(n.z_m))
      return fmt::format("neighbour {} at ({}, {}, {}) m is not finite", n.agent_id, n.position.x, n.position.y, n.z_m);
    if (!(n.radius_m >= 0.0 && n.radius_m <= 1e3))
      return fmt::format("neighbour {} has a body radius of {} m, not in [0, 1000] m", n.agent_id, n.radius_m);
  }
  return {};
}

FrameGate::FrameGate(std::uint32_t agent_id, Assignment assignment, SensorSpec sensor, bus::WriterId world)
    : agent_id_(agent_id), assignment_(std::move(assignment)), sensor_(std::move(sensor)), world_(world) {}

FrameJudgement FrameGate::judge(const protocol::SensorFrame& frame, const bus::WriterId& from) const {
  // Only the world that admitted this agent speaks for the run; what it sends must make sense.
  if (from != world_)
    return {FrameCall::kIgnored,
            fmt::format("written by participant {}, not by the world this agent was admitted to ({})", from.to_string(),
                        world_.to_string())};
  if (frame.agent_id != agent_id_) return {FrameCall::kIgnored, fmt::format("addressed to agent {}", frame.agent_id)};
  // A standing request answers any number of steps the world holds back (docs/runtime.md#standing-answers).
  const bool stood = !sent_.empty() && sent_.back().second.standing;
  if (answered_any_ && !stood && frame.step > last_answered_ && frame.step - last_answered_ > kMaxStepsAhead)
    return {FrameCall::kIgnored, fmt::format("step {} is more than {} steps ahead of the last one answered ({})",
                                             frame.step, kMaxStepsAhead, last_answered_)};
  std::string problem = frame_problem(frame, assignment_, sensor_);
  if (!problem.empty()) return {FrameCall::kIgnored, std::move(problem)};
  if (frame.run_over) return {FrameCall::kRunOver, {}};
  if (answered_any_ && frame.step == last_answered_) return {FrameCall::kRepeat, {}};
  if (answered_any_ && frame.step < last_answered_) {
    if (from == answered_world_) return {FrameCall::kStale, {}};
    if (request_for(frame.step)) return {FrameCall::kRepeat, {}};
  }
  return {FrameCall::kDecide, {}};
}

void FrameGate::answered(std::uint64_t step, protocol::ActionRequest request) {
  while (!sent_.empty() && sent_.back().first >= step) sent_.pop_back();
  sent_.emplace_back(step, std::move(request));
  if (sent_.size() > kRequestHistory) sent_.pop_front();
  answered_any_ = true;
  last_answered_ = step;
  answered_world_ = world_;
}

std::optional<protocol::ActionRequest> FrameGate::request_for(std::uint64_t step) const {
  // The first kept request after `step`; the one before it answered `step` or, standing, the steps up to the next.
  const auto after = std::upper_bound(sent_.begin(), sent_.end(), step,
                                      [](std::uint64_t s, const auto& sent) { return s < sent.first; });
  if (after == sent_.begin()) return std::nullopt;
  const auto& [answered, request] = *std::prev(after);
  if (answered == step) return request;
  if (!request.standing || step > last_answered_) return std::nullopt;
  protocol::ActionRequest stood = request;
  stood.step = step;
  return stood;
}

}  // namespace marsala::agent::runtime
