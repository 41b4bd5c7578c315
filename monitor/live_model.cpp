#include "marsala/monitor/live_model.hpp"

#include <fmt/format.h>


#include <nlohmann/json.hpp>

#include "marsala/monitor/format.hpp"
#include "marsala/render/terrain_renderer.hpp"

namespace marsala::monitor {
namespace {

using nlohmann::json;

/// The window of world wall time over which steps/s is measured [s].
constexpr double kRateWindowS = 2.0;

std::string hex_colour(render::Rgb c) { return fmt::format("#{:02x}{:02x}{:02x}", c.r, c.g, c.b); }

json rectangle(const Rect& r) { return {{"x0", r.x0}, {"y0", r.y0}, {"x1", r.x1}, {"y1", r.y1}}; }
json point(const Position& p) { return json::array({p.x, p.y}); }

json scene_json(const LiveScene& s) {
  json j = {{"completion", s.completion},
            {"base", {{"x", s.base.x}, {"y", s.base.y}, {"r", s.base_radius_m}}},
            {"targets", json::array()}};
  if (s.goal) j["goal"] = rectangle(*s.goal);
  if (s.site) j["site"] = rectangle(*s.site);
  if (s.payload) j["payload"] = {{"from", point(s.payload->first)}, {"to", point(s.payload->second)}};
  for (const auto& [id, at] : s.targets) j["targets"].push_back({{"id", id}, {"x", at.x}, {"y", at.y}});
  return j;
}

json map_json(const LiveMap& m) {
  const GridGeometry& g = m.geometry;
  json j = {{"xll", g.xll_m},
            {"yll", g.yll_m},
            {"rows", g.rows},
            {"cols", g.cols},
            {"cell_size_m", g.cell_size_m},
            {"width_m", g.cols * g.cell_size_m},
            {"height_m", g.rows * g.cell_size_m},
            {"min_height_m", m.min_height_m},
            {"max_height_m", m.max_height_m},
            {"image_width_px", m.image_width_px},
            {"image_height_px", m.image_height_px},
            {"version", m.version},
            {"log_steps", m.log_steps}};
  j["scene"] = m.scene ? scene_json(*m.scene) : json(nullptr);
  return j;
}

const char* run_phase(const protocol::WorldStatus& s) {
  if (s.admitting) return "admitting";
  if (s.running) return "running";
  return s.completed ? "completed" : "ended";
}

}  // namespace

std::string to_string(RobotRole role) {
  switch (role) {
    case RobotRole::kActive: return "active";
    case RobotRole::kFollowing: return "following";
    case RobotRole::kReturning: return "returning";
    case RobotRole::kDone: return "done";
    case RobotRole::kDropped: return "dropped";
    case RobotRole::kWaiting: break;
  }
  return "waiting";
}

RobotRole role_of(const std::string& state, bool alive) {
  if (!alive) return RobotRole::kDropped;
  if (state == "survey" || state == "advance" || state == "build" || state == "retreat" || state == "active")
    return RobotRole::kActive;
  if (state == "follow" || state == "hold" || state == "back_off") return RobotRole::kFollowing;
  if (state == "return_to_base") return RobotRole::kReturning;
  if (state == "done" || state == "at_goal") return RobotRole::kDone;
  return RobotRole::kWaiting;
}

LiveModel::LiveModel(std::string source, bool replay) : source_(std::move(source)), replay_(replay) {}

void LiveModel::on_status(const protocol::WorldStatus& status, Clock::time_point now) {
  const bool other_run = status_ && (status.run_id != status_->run_id || status.world_id != status_->world_id);
  if (other_run) {
    rate_window_.clear();
    events_.clear();
  }
  // A transient-local replay may arrive after a newer live sample: never step back within one run.
  if (status_ && !other_run && status.step < status_->step && status.running) return;
  status_ = status;
  status_time_ = now;
  ++statuses_;
  if (status.running && !status.admitting) {
    rate_window_.emplace_back(status.wall_seconds, status.step);
    while (rate_window_.size() > 2 && rate_window_.back().first - rate_window_[1].first >= kRateWindowS)
      rate_window_.pop_front();
  }
}

void LiveModel::on_event(const protocol::WorldEvent& event) {
  events_.push_back(event);
  while (events_.size() > kMaxEvents) events_.pop_front();
}

void LiveModel::set_map(const LiveMap& map) {
  map_ = map;
  map_note_.clear();
}

void LiveModel::set_map_note(std::string note) { map_note_ = std::move(note); }

double LiveModel::steps_per_second() const {
  if (rate_window_.size() < 2) return 0.0;
  const double dt = rate_window_.back().first - rate_window_.front().first;
  const double steps = static_cast<double>(rate_window_.back().second - rate_window_.front().second);
  return dt > 0.0 ? steps / dt : 0.0;
}

std::string LiveModel::state_json(Clock::time_point now) const {
  json j = {{"source", source_}, {"replay", replay_}, {"version", statuses_}};
  json palette = json::array();
  for (const render::Rgb& c : render::default_palette()) palette.push_back(hex_colour(c));
  j["palette"] = palette;
  if (status_) {
    const protocol::WorldStatus& s = *status_;
    const double mean_rate = s.wall_seconds > 0.0 ? static_cast<double>(s.step) / s.wall_seconds : 0.0;
    j["run"] = {{"run_id", printable(s.run_id)},
                {"scenario", printable(s.scenario)},
                {"step", s.step},
                {"wall_s", s.wall_seconds},
                {"progress", s.progress},
                {"progress_detail", printable(s.progress_detail)},
                {"phase", run_phase(s)},
                {"running", s.running},
                {"completed", s.completed},
                {"deposited_m3", s.deposited_volume_m3},
                {"steps_per_s", s.running ? steps_per_second() : mean_rate},
                {"mean_steps_per_s", mean_rate},
                {"status_age_s", std::chrono::duration<double>(now - status_time_).count()}};
    json agents = json::array();
    for (const protocol::AgentStatus* a : agents_by_id(s))
      agents.push_back({{"id", a->agent_id},
                        {"name", printable(a->name)},
                        {"state", printable(a->state)},
                        {"role", to_string(a->at_goal && a->alive ? RobotRole::kDone : role_of(a->state, a->alive))},
                        {"x", a->x_m},
                        {"y", a->y_m},
                        {"z", a->z_m},
                        {"material_m3", a->material_m3},
                        {"deposited_m3", a->deposited_m3},
                        {"accepted", a->accepted},
                        {"rejected", a->rejected},
                        {"missed", a->missed},
                        {"alive", a->alive},
                        {"at_goal", a->at_goal}});
    j["agents"] = agents;
  } else {
    j["run"] = nullptr;
    j["agents"] = json::array();
  }
  json events = json::array();
  for (auto it = events_.rbegin(); it != events_.rend(); ++it) {
    events.push_back({{"step", it->step},
                      {"agent", it->agent_id},
                      {"kind", event_kind(it->kind)},
                      {"volume_m3", it->volume_m3},
                      {"detail", printable(it->detail)}});
  }
  j["events"] = events;
  j["map"] = map_ ? map_json(*map_) : json(nullptr);
  j["map_note"] = map_note_;
  // Non-UTF-8 bytes cannot occur (printable() keeps ASCII); replace rather than throw all the same.
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace marsala::monitor
