#pragma once
// A run's progress for people: how often tail prints a step line (--every, --interval), the step rate and the time
// left estimated from the world's statuses, and `marsala-monitor progress`, one line kept up to date in place on a
// terminal (deploy/spawn.sh shows it while a run goes):
//
//   step 730 | 52.3 % | 412 steps/s | ETA 3 s | 6.94 of 14.48 m3 of MARS gap left on the route
//
// Rates and estimates use the world's own clock (WorldStatus.wall_seconds), never the monitor's, so they do not
// depend on when statuses arrive.

#include <chrono>
#include <cstdint>
#include <deque>
#include <iosfwd>
#include <optional>
#include <string>

#include "marsala/bus/bus.hpp"
#include "marsala/monitor/stop_source.hpp"
#include "marsala/protocol/messages.hpp"

namespace marsala::monitor {

/// Reader history of the world's status topic, for tail and progress: statuses come once per step and a slow terminal
/// must not make them skip steps (the world keeps only the latest, depth 1) [samples].
inline constexpr std::int32_t kStatusDepth = 64;

/// A duration in seconds as a steady clock's duration.
inline std::chrono::steady_clock::duration to_clock(std::chrono::duration<double> d) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(d);
}

/// Which step lines tail prints: all of them by default; with every_steps N, the first status and then one whenever
/// the step crosses a multiple of N; with an interval S, at most one every S seconds (monitor clock); with both, a
/// line when both allow it.
class LinePacing {
 public:
  using Clock = std::chrono::steady_clock;

  /// every_steps: 0 or 1 = every step; interval: zero = no limit [s].
  LinePacing(std::uint64_t every_steps = 0, std::chrono::duration<double> interval = {});

  /// True when the status of `step` seen at `now` gets its line (and remembers it as printed).
  bool take(std::uint64_t step, Clock::time_point now);

 private:
  std::uint64_t every_steps_;
  Clock::duration interval_;
  std::optional<std::uint64_t> last_step_;
  Clock::time_point last_time_{};
};

/// Step rate and time to completion from the statuses of one run, over a sliding window of the world's wall time.
class ProgressMeter {
 public:
  /// window_s: how much of the run's recent history the rates use [s] (> 0).
  explicit ProgressMeter(double window_s = 30.0);

  /// Takes a status of the run (statuses while admitting, and older steps than the latest, are ignored).
  void add(double wall_seconds, std::uint64_t step, double progress);

  /// Steps per second of the world's wall time over the window; 0 until two statuses a moment apart.
  double steps_per_s() const;
  /// Seconds until progress 1 at the window's rate of progress; none when progress did not rise in the window.
  std::optional<double> eta_s() const;

 private:
  struct Sample {
    double wall_s;
    std::uint64_t step;
    double progress;
  };
  double window_s_;
  std::deque<Sample> samples_;
};

/// "< 1 s", "3 s", "2 min 05 s", "1 h 02 min": a duration for people; "-" for none.
std::string format_duration(std::optional<double> seconds);

/// The progress line of `status`: running: step, progress, rate, ETA, detail; admitting: the agents admitted so far;
/// over: the outcome, steps and wall time. At most `width` columns (0: no limit).
std::string format_progress_line(const protocol::WorldStatus& status, const ProgressMeter& meter, int width = 0);

/// Options of `marsala-monitor progress`.
struct ProgressOptions {
  bool in_place = false;  ///< rewrite one line ("\r", erase to its end) instead of printing new ones
  int width = 0;          ///< longest line [columns]; 0 = no limit
  /// Shortest time between two lines (in place: between two rewrites) [s].
  std::chrono::duration<double> interval = std::chrono::milliseconds(250);
  std::optional<std::chrono::duration<double>> timeout;  ///< exit 1 after this long without a status
  std::string run_id;                                    ///< follow this run only; empty = the first run seen
};

/// Follows the world's statuses and prints the progress line until the run ends (its last line, then 0), `stop` is
/// requested (0) or no status came for options.timeout (a message on `err`, 1). In place, the line ends with a newline
/// only when the program leaves.
int run_progress(bus::Participant& participant, const ProgressOptions& options, const StopSource& stop,
                 std::ostream& out, std::ostream& err);

}  // namespace marsala::monitor
