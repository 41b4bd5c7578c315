#pragma once
// The wire contract as plain C++ structs: what agents, the world server and the monitor exchange.
// They are built from the core's vocabulary (RobotBody); idl/marsala.idl mirrors them field for field (all @final)
// and the DDS backends in common/bus convert between the two, so no other code ever sees a vendor type. The rules
// that give each message its meaning are docs/runtime.md.
//
// Units: positions and lengths [m] in the world frame of ARCHITECTURE.md (x east, y north), heights [m],
// volumes [m^3], slopes rise over run [m/m]. Steps count lockstep ticks from 0.

#include <cstdint>
#include <string>
#include <vector>

#include "marsala/core/assignment.hpp"
#include "marsala/core/robot_body.hpp"
#include "marsala/core/sensor_spec.hpp"

namespace marsala::protocol {

// Core vocabulary the messages carry as it is.
using marsala::Deposit;
using marsala::Deposition;
using marsala::Neighbour;
using marsala::ScanPoint;
using marsala::TerrainTile;

/// Agent -> world, repeated until admitted: who I am and what my body can do.
struct AgentHello {
  std::uint32_t agent_id = 0;  ///< unique in the run, >= 1
  std::uint64_t session = 0;   ///< random per process start, so a restarted agent is told apart
  std::string name;            ///< human-readable, e.g. "builder-3"
  std::string behaviour;       ///< reactive behaviour name, e.g. "ramp_builder"
  RobotBody body;              ///< declared body; admitted only if equal to its slot's robot type
};

/// World -> agent: the answer to a hello, with what the agent needs to build its own map.
struct Admission {
  std::uint32_t agent_id = 0;
  std::uint64_t session = 0;  ///< echoes the hello's session
  bool accepted = false;
  std::string reason;     ///< why not, when rejected
  std::string run_id;     ///< names the run; the agent's endpoints use partition_for(run, id, session)
  Assignment assignment;  ///< when accepted: grid, tile size, start, target and base station
  std::string world_key;    ///< the run's public key, 64 hex digits (world_proof.hpp)
  std::string world_proof;  ///< the world's signature of (run, its participant), 128 hex digits (world_proof.hpp)
};

/// Outcome of an agent's previous request, reported in its next frame.
enum class ActionResult : std::uint8_t { kNone = 0, kAccepted = 1, kRejected = 2, kMissed = 3 };

/// World -> one agent (its own partition only): what its sensors see at the start of `step`.
struct SensorFrame {
  std::uint32_t agent_id = 0;
  std::uint64_t step = 0;
  double x_m = 0.0;  ///< pose: the world's record of where the robot stands [m]
  double y_m = 0.0;
  double z_m = 0.0;          ///< terrain height under the robot's centre [m]
  double material_m3 = 0.0;  ///< material on board [m^3]
  ActionResult last_result = ActionResult::kNone;
  std::string last_reason;            ///< why the previous request was rejected, if it was
  std::vector<TerrainTile> tiles;     ///< tiles in sensing range that changed since this agent last got them
  std::vector<Neighbour> neighbours;  ///< robots within proximity range
  bool run_over = false;              ///< the run has ended: the agent should exit
  /// A laser or rgbd scan was taken for this frame (its points may still be none: every ray missed).
  bool scanned = false;
  /// The scan: hits as offsets from the sensor origin (the robot's position, terrain height under it plus the
  /// sensor's mount height) in world-aligned axes [m]; empty when not scanned.
  std::vector<ScanPoint> points;
};

/// Agent -> world (its own partition only): what it wants to do in `step`.
struct ActionRequest {
  std::uint32_t agent_id = 0;
  std::uint64_t session = 0;
  std::uint64_t step = 0;
  bool move = false;  ///< move to (target_x_m, target_y_m) this step
  double target_x_m = 0.0;
  double target_y_m = 0.0;
  std::vector<Deposition> depositions;  ///< applied after the motion, within reach of the new position (layer)
  std::vector<Deposit> deposits;        ///< same, for a cube or cone depositor: the world gives them their shape
  bool refill = false;                  ///< top up material (only at the base station)
  std::string state;                    ///< the behaviour's state name, for the monitor
  /// What keeps the robot from going on, in a few words ("front neighbour 7 at 1.4 m (hold)"); empty when nothing
  /// does. For people (the world's stall account); the world keeps a bounded, printable copy.
  std::string waiting_for;
  /// How long the decision behind this request took, wall clock and the deciding thread's CPU [us] (0: not said).
  /// For the step trace only: never part of the request's meaning, so same_request() and the run log ignore them.
  std::uint32_t decision_us = 0;
  std::uint32_t decision_cpu_us = 0;  ///< [us]
  /// This (empty) request is the agent's answer to every later frame that tells it nothing new: the world writes it
  /// no frame meanwhile and takes this answer for it (docs/runtime.md#standing-answers).
  bool standing = false;
};

/// One agent as the world sees it, for status and the monitor.
struct AgentStatus {
  std::uint32_t agent_id = 0;
  std::string name;
  std::string state;
  double x_m = 0.0;
  double y_m = 0.0;
  double z_m = 0.0;
  double material_m3 = 0.0;
  double deposited_m3 = 0.0;
  std::uint32_t accepted = 0;  ///< requests accepted
  std::uint32_t rejected = 0;  ///< requests rejected
  std::uint32_t missed = 0;    ///< steps whose deadline passed without its request
  bool alive = true;
  bool at_goal = false;
  std::string waiting_for;  ///< what its latest request said it waits for, as the world keeps it
};

/// World -> everyone, once per step (transient-local, so a late monitor sees the latest at once).
struct WorldStatus {
  std::string run_id;
  std::string scenario;
  std::uint64_t step = 0;
  double wall_seconds = 0.0;
  double deposited_volume_m3 = 0.0;
  double progress = 0.0;  ///< [0, 1]: agents at goal (fraction), payload route's gap filled, site level fraction
  bool running = true;
  bool completed = false;
  std::vector<AgentStatus> agents;
  std::uint64_t world_id = 0;  ///< random per world process: tells two worlds on one domain apart
  bool admitting = false;      ///< the world is still admitting its agents (before its first step)
  std::string progress_detail;  ///< the progress in words, e.g. "12.31 of 21.30 m3 of MARS gap left on the route"
  std::uint32_t team_size = 0;  ///< slots of the run's team (--agents), admitted or not [count]; 0 = not said
  std::string world_key;        ///< the run's public key, 64 hex digits (world_proof.hpp)
  std::string world_proof;      ///< the world's signature of (run, its participant), 128 hex digits (world_proof.hpp)
};

/// Kinds of world events, for the event stream and the monitor.
enum class EventKind : std::uint8_t {
  kAdmitted = 0,
  kRefused = 1,
  kRejected = 2,
  kDeposited = 3,
  kMissed = 4,
  kDropped = 5,
  kAtGoal = 6,
  kRunOver = 7,
};

/// World -> everyone: something happened.
struct WorldEvent {
  std::uint64_t step = 0;
  std::uint32_t agent_id = 0;  ///< 0 when not about one agent
  EventKind kind = EventKind::kAdmitted;
  double volume_m3 = 0.0;  ///< for kDeposited
  std::string detail;
};

/// The partition that carries the frames and requests of one agent process (its session) in one run:
/// "<run_id>/agent-<id>-<session, 16 hex digits>". Every process has a partition of its own, so the world counts only
/// that process's endpoints as ready, and a process that left (or merely listens) never takes a successor's frames.
std::string partition_for(const std::string& run_id, std::uint32_t agent_id, std::uint64_t session);

/// True when the two requests are the same in every field (an agent that repeats a request it already sent).
bool same_request(const ActionRequest& a, const ActionRequest& b);
/// True when `a` and `b` are the same bits: how the contract compares its doubles (a NaN equals itself).
bool same_bits(double a, double b);

/// Names of the enums, for logs and the monitor; from_string throws InvalidArgument listing valid names.
std::string to_string(ActionResult r);
std::string to_string(EventKind k);
EventKind event_kind_from_string(const std::string& name);

/// The enum a wire octet encodes; throws InvalidArgument ("malformed ...") for a value the protocol does not define,
/// so a converter drops the sample instead of passing a value no switch expects.
ActionResult action_result_from_wire(std::uint8_t value);
EventKind event_kind_from_wire(std::uint8_t value);

}  // namespace marsala::protocol
