#pragma once
// What the live view shows (marsala-monitor serve), gathered from what the monitor may read and published to
// browsers as one JSON document (docs/runtime.md#live-view):
//
//   WorldStatus (DDS)  --on_status-->  run line, steps/s, agents and their roles  --+
//   WorldEvent (DDS)   --on_event--->  the latest events                             +--> state_json()
//   run.log + terrain_initial.asc --set_map-->  terrain picture, scene geometry   --+
//
// In a replay the statuses are made from the run log instead of DDS. The model holds data only: no IO, no threads;
// callers serialise access (serve.cpp holds one lock around it).

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/types.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::monitor {

/// A robot's role in the live view, from its behaviour state (the agents' state names, agent/reactive/).
enum class RobotRole : std::uint8_t {
  kActive = 0,     ///< surveys, advances to, builds at or retreats from its construction front
  kFollowing = 1,  ///< follows, holds or backs off behind its front neighbour (the pipeline)
  kReturning = 2,  ///< on its way back to the base to refill
  kDone = 3,       ///< at its goal or finished (the page also shows an agent the world reports at its goal as done)
  kDropped = 4,    ///< no longer live (dropped by the world)
  kWaiting = 5,    ///< no state yet (admitted, before its first request) or a state the view does not know
};

/// "active", "following", "returning", "done", "dropped", "waiting".
std::string to_string(RobotRole role);
/// The role of a robot whose latest behaviour state is `state`: survey, advance, build, retreat -> active; follow,
/// hold, back_off -> following; return_to_base -> returning; done, at_goal -> done; a robot that is not `alive` is
/// dropped whatever its state; anything else (empty included) -> waiting.
RobotRole role_of(const std::string& state, bool alive);

/// Where the scenario puts things, for the overlays (from the scenario text in the run log's header).
struct LiveScene {
  std::string completion;  ///< "agents_at_goal", "payload_path" or "level_site"
  Position base;              ///< the base's centre [m]
  double base_radius_m = 0.0;  ///< [m]
  std::optional<Rect> goal;    ///< agents_at_goal [m]
  std::optional<Rect> site;    ///< level_site [m]
  /// payload_path: the payload's start and destination [m].
  std::optional<std::pair<Position, Position>> payload;
  /// Each slot's target [m], by agent id.
  std::vector<std::pair<std::uint32_t, Position>> targets;
};

/// The terrain picture the view shows and what it covers.
struct LiveMap {
  GridGeometry geometry;        ///< the run's grid: the picture covers it exactly, north up
  double min_height_m = 0.0;    ///< lowest and highest cell of the pictured terrain [m]
  double max_height_m = 0.0;
  int image_width_px = 0;       ///< the picture's size [px]
  int image_height_px = 0;
  std::uint64_t version = 0;    ///< grows with every new picture; the page fetches the picture again when it changes
  std::uint64_t log_steps = 0;  ///< steps of the run log the picture includes
  std::optional<LiveScene> scene;
};

/// The live view's data.
class LiveModel {
 public:
  using Clock = std::chrono::steady_clock;

  /// `source` says where the data comes from, for the page (e.g. "DDS domain 61 (cyclone)", "replay of out/run").
  explicit LiveModel(std::string source, bool replay = false);

  /// Takes a world status received at `now`. A status of another run or world (run_id or world_id changed) starts
  /// the view afresh: a new run on the domain.
  void on_status(const protocol::WorldStatus& status, Clock::time_point now);
  /// Keeps the event among the latest kMaxEvents.
  void on_event(const protocol::WorldEvent& event);
  /// A new terrain picture (or scene) described by `map`.
  void set_map(const LiveMap& map);
  /// What the page says about the terrain while there is none (e.g. "waiting for out/run/run.log"); empty = nothing.
  void set_map_note(std::string note);

  /// Steps per second over the latest statuses (about the last 2 s of the world's wall time); 0 before two steps.
  double steps_per_second() const;
  /// The latest status, if any.
  const std::optional<protocol::WorldStatus>& status() const { return status_; }

  /// The document the page reads (/api/state): source, run line, steps/s, agents with roles, latest events, map and
  /// scene, palette; `version` counts the statuses taken. Text from the wire is passed through printable().
  std::string state_json(Clock::time_point now) const;

  static constexpr std::size_t kMaxEvents = 12;

 private:
  std::string source_;
  bool replay_;
  std::optional<protocol::WorldStatus> status_;
  Clock::time_point status_time_{};
  std::uint64_t statuses_ = 0;
  std::deque<std::pair<double, std::uint64_t>> rate_window_;  ///< (wall_seconds, step) of recent running statuses
  std::deque<protocol::WorldEvent> events_;
  std::optional<LiveMap> map_;
  std::string map_note_;
};

}  // namespace marsala::monitor
