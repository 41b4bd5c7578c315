#pragma once
// The runtime of marsala-monitor: reads WorldStatus and WorldEvent from a participant and prints them.
// It creates readers only (never a writer), so it joins and leaves a running system without disturbing it.
// Statuses are read transient-local: a monitor that starts late sees the latest step at once.

#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include "marsala/bus/bus.hpp"
#include "marsala/monitor/format.hpp"
#include "marsala/monitor/stop_source.hpp"

namespace marsala::monitor {

/// Options of `tail`.
struct TailOptions {
  std::string run_id;                                    ///< follow this run only; empty = the first run seen
  bool events = false;                                   ///< also print one line per WorldEvent
  std::optional<std::chrono::duration<double>> timeout;  ///< give up after this long without a status [s]; none = never
  /// How long to wait for late events (up to kRunOver) once the final status arrived [s].
  std::chrono::duration<double> drain = std::chrono::milliseconds(500);
  FormatOptions format;
  std::uint64_t every_steps = 0;            ///< a step line whenever the step crosses a multiple of this; 0 = all
  std::chrono::duration<double> interval{};  ///< at most a step line this often [s]; zero = no limit
  /// Once a status of the run came: end (kExitWorldGone) when no status writer has been alive for this long [s]
  /// (the world died, was killed, or is paused or cut off that long); zero = never.
  std::chrono::duration<double> gone_after = std::chrono::seconds(10);
};

/// tail's exit code when the world of the run it follows is gone (TailOptions::gone_after).
inline constexpr int kExitWorldGone = 3;

/// Options of `status`.
struct StatusOptions {
  std::chrono::duration<double> timeout = std::chrono::seconds(5);  ///< how long to wait for a world [s]
  /// How long it goes on listening after the first status it believes, so that another publisher of the run's
  /// statuses is named even when its status arrives after the world's [s].
  std::chrono::duration<double> listen = std::chrono::seconds(1);
};

/// Prints one line per step (and per event) until the run ends (final summary, 0), `stop` is requested
/// (0), no status came for options.timeout (message on `err`, 1), or the run's world is gone: no live status writer
/// for options.gone_after (a last line on `out`, the reason on `err`, kExitWorldGone). Statuses of other runs are
/// skipped.
int run_tail(bus::Participant& participant, const TailOptions& options, const StopSource& stop, std::ostream& out,
             std::ostream& err);

/// Waits for a WorldStatus it believes, listens options.listen longer (statuses of another publisher are named on
/// `err`, never believed), and prints the newest believed status as a table (0); no status within options.timeout
/// or `stop` requested first: a message on `err` and 1.
int run_status(bus::Participant& participant, const StatusOptions& options, const StopSource& stop, std::ostream& out,
               std::ostream& err);

}  // namespace marsala::monitor
