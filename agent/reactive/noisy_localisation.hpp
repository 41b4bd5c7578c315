#pragma once
// A robot that does not know exactly where it stands (docs/runtime.md#localisation-error): wraps the behaviour of a
// robot type whose localisation has noise_sd_m > 0. Each frame the pose error e of this step
// (executive/pose_error.hpp) is rounded to whole cells k, the map's resolution, and everything the robot places by
// its own pose moves by k: its position, its neighbours (proximity sensing is relative) and the terrain of its
// sensing window (registered at k: set_registration; the world sends only tiles that changed, the sensor sees its
// whole window, so tiles received earlier are registered again from a cache). Its actuators carry out what it asked
// from where it truly is: a motion to believed target T goes to T - k cs, a deposition on believed cell c lands on
// world cell c - k (dropped when off the grid), a cube or cone deposit at believed point p at p - k cs.
// A scanning robot's scans are the exception: they go in from the sensor origin it believes, true + e, so hits land
// displaced by the whole error e, continuously (set_sub_cell_error: e - k cs).
//
// Within one frame pose, map and actions agree, as for a robot without error: what the error changes is where the
// robot puts everything given in world coordinates (its target, the base station, the arrows of a goal vector map),
// and its memory: terrain outside the window stays registered at the error it had when last seen, and the trajectory
// and the construction's history jump when k changes. Two robots also place the same cells differently.

#include <map>
#include <memory>
#include <string>
#include <utility>

#include "marsala/agent/executive/pose_error.hpp"
#include "marsala/agent/reactive/behaviour.hpp"

namespace marsala::agent::reactive {

/// The whole-cell offset of a pose error `error` [m] (believed = true + error) on cells of cell_size_m [m]: world
/// cell (r, c) is believed at (r + offset.row, c + offset.col); offset = (-floor(0.5 + e_y / cs), floor(0.5 + e_x / cs)).
CellIndex registration_offset(Position error, double cell_size_m);

/// A behaviour acting on a noisy belief of its own pose.
class NoisyLocalisation final : public Behaviour {
 public:
  /// Wraps the behaviour `inner_name` made for `context`; throws InvalidArgument for an unknown name or a
  /// localisation spec out of range.
  NoisyLocalisation(const AgentContext& context, const std::string& inner_name);

  std::string name() const override { return inner_->name(); }
  std::string state_name() const override { return inner_->state_name(); }
  std::string waiting_for() const override { return inner_->waiting_for(); }
  void on_admission(const protocol::Admission& admission) override;
  protocol::ActionRequest decide(const protocol::SensorFrame& frame) override;
  std::optional<deliberative::KnownMap> known_map() const override { return inner_->known_map(); }

  /// The error of the last frame decided [m], as drawn.
  Position last_error() const { return error_; }
  /// The same in whole cells: world cell (r, c) was believed at (r + row, c + col) (held so the belief stays on the grid).
  CellIndex last_offset() const { return offset_; }
  /// The wrapped behaviour (made anew on admission).
  const Behaviour& inner() const { return *inner_; }

 private:
  AgentContext context_;
  std::string inner_name_;
  std::unique_ptr<Behaviour> inner_;
  executive::PoseError pose_error_;
  GridGeometry world_;
  int tile_size_ = 16;
  /// Every tile received, as last received (world-registered), by (tile row, tile col): the sensor sees its whole
  /// window every frame, while the world sends only tiles that changed; each frame the tiles in the window are
  /// registered again at the current error.
  std::map<std::pair<int, int>, TerrainTile> sensed_;
  bool admitted_ = false;
  Position error_;
  CellIndex offset_{0, 0};
};

}  // namespace marsala::agent::reactive
