#pragma once
// marsala-world --trace FILE: the lockstep as a Chrome trace (the trace-event JSON format that Perfetto and
// chrome://tracing open; docs/runtime.md#step-traces). One track for the world (each step and its phases: frames out,
// the wait for requests, validation and application, the record; then the status) and one per agent (its wait: from
// the step's frames to its answer), so a step's straggler is the longest bar under it.
//
// The file is written as the run goes to FILE.tmp and renamed to FILE when the run is over; a run that fails leaves
// no FILE.tmp behind.

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace marsala::world_server {

/// The world's track in a trace (an agent's track is its id).
inline constexpr std::uint32_t kWorldTrack = 0;

/// One complete event ("ph":"X") of a trace.
struct TraceSpan {
  std::uint32_t track = kWorldTrack;  ///< kWorldTrack or an agent id
  std::string name;                   ///< "step", "frames", "collect", "apply", "record", "status", "answer", "missed"
  double start_us = 0.0;              ///< from the trace's origin [us]
  double duration_us = 0.0;           ///< [us]
  std::uint64_t step = 0;             ///< the step it belongs to
  double cpu_us = -1.0;               ///< a decision's CPU time, in the event's args when >= 0 [us]
};

/// `span` as one JSON object of the trace-event format: {"name","cat","ph":"X","ts","dur","pid","tid","args":{"step"}},
/// times with nanosecond digits.
std::string trace_event_json(const TraceSpan& span);

/// One agent's answer to a step: when the world read it, and the decision time the agent reported in it.
struct AgentAnswer {
  std::uint32_t agent = 0;                     ///< its id
  std::chrono::steady_clock::time_point read;  ///< when the world read the request
  std::uint32_t decision_us = 0;               ///< the agent's decision, wall clock (0: not said) [us]
  std::uint32_t decision_cpu_us = 0;           ///< the same, the deciding thread's CPU time [us]
};

/// The times of one step's phases, read from the world's clock as it ran (steady_clock).
struct StepTimes {
  using Clock = std::chrono::steady_clock;
  std::uint64_t step = 0;       ///< the step applied
  Clock::time_point start;      ///< before its frames went out
  Clock::time_point frames_out;  ///< its frames written
  Clock::time_point collected;  ///< the wait for requests over
  Clock::time_point applied;    ///< apply_step done
  Clock::time_point recorded;   ///< run.log (and snapshot) written: the end of the step's time in summary.json
  Clock::time_point published;  ///< notes, events and WorldStatus out
  std::vector<AgentAnswer> answers;   ///< each agent that answered, when it was read
  std::vector<std::uint32_t> missed;  ///< the live agents that did not answer
};

/// The spans of one step: on the world's track "step" (start to recorded) and its phases "frames", "collect",
/// "apply", "record" that tile it, then "status" (recorded to published); on each agent's track "answer" (frames out
/// to its answer) or "missed" (frames out to the end of the wait). Inside an "answer", "decide": the decision the
/// agent reported, ending where the answer was read (the agents share no clock with the world, so it is placed as
/// late as it can have been; no longer than the answer, with its CPU time in args). Times from `origin` [us].
std::vector<TraceSpan> step_spans(const StepTimes& times, StepTimes::Clock::time_point origin);

/// A trace being written.
class StepTrace {
 public:
  /// Opens `path`.tmp for writing, times counted from `origin`; throws IoError naming the file when it cannot.
  StepTrace(std::string path, StepTimes::Clock::time_point origin);
  /// Removes `path`.tmp unless finish() was called.
  ~StepTrace();
  StepTrace(const StepTrace&) = delete;
  StepTrace& operator=(const StepTrace&) = delete;

  /// Names the tracks of agents 1..agents ("agent N"), besides the world's.
  void name_tracks(std::uint32_t agents);
  /// Appends the spans of one step; throws IoError when the file cannot be written.
  void step(const StepTimes& times);
  /// Closes the JSON and renames `path`.tmp to `path`; throws IoError when it cannot.
  void finish();

 private:
  void write(const std::string& text);

  std::string path_;
  StepTimes::Clock::time_point origin_;
  std::FILE* file_ = nullptr;
  bool finished_ = false;
};

}  // namespace marsala::world_server
