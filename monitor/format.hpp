#pragma once
// What marsala-monitor prints, as pure functions of the messages it reads (no IO, no state).
//
// tail, one line per step, under a column header (printed again whenever the team's ids change):
//
//     step  live mat[m3]  dep[m3] prog | 1           2           3
//       42   2/3    3.75    0.125  33% | build       refill*     --
//
//   mat = material on board of the live agents, dep = volume deposited in the run, prog = the run's progress
//   [%] (WorldStatus.progress: agents at the goal, the payload route's gap filled, the site's level); then one column per agent in id order: its behaviour state ("*" at its goal, "--" dropped,
//   "?" no state yet), cut to the column width. When the agents do not fit the line width (more than 12 at
//   100 columns), the columns give way to a count of live agents per state: "| build 9, refill 3".
// tail --events, one line per WorldEvent:   "    42 > agent 3  deposited 0.000125 m3 5 cells"
// status, a one-shot table: run line, column header, one row per agent, totals.
//
// Text from the wire (names, states, details, run ids) is printed with control and non-ASCII bytes
// replaced by '?', so nothing a process sends can drive the terminal or break the alignment.

#include <cstddef>
#include <string>
#include <vector>

#include "marsala/protocol/messages.hpp"

namespace marsala::monitor {

/// Layout of the tail view.
struct FormatOptions {
  int width = 100;  ///< longest line [columns]; longer lines end in "..."; 0 = no limit
};

/// Width of the tail view's fixed columns, up to and including " |" [columns].
inline constexpr int kStepPrefixWidth = 36;
/// Widest text of one agent column of the tail view [columns].
inline constexpr int kMaxAgentColumnText = 11;
/// Narrowest text of one agent column; below it the tail view counts agents per state [columns].
inline constexpr int kMinAgentColumnText = 4;

/// Text width of one agent column for `agent_count` agents, or 0 when they do not fit (per-state counts).
int agent_column_text_width(std::size_t agent_count, const FormatOptions& options = {});

/// The tail view's column header for the agents of `status`.
std::string format_step_header(const protocol::WorldStatus& status, const FormatOptions& options = {});
/// The tail view's line for one step.
std::string format_step_line(const protocol::WorldStatus& status, const FormatOptions& options = {});
/// The line tail prints last, once the run has ended: outcome, agents, the team's slots not in the run (dropped or
/// never admitted), volume and request counts.
std::string format_run_summary(const protocol::WorldStatus& status);
/// One line per world event: step, agent (or "world"), kind, volume when deposited, detail.
std::string format_event(const protocol::WorldEvent& event, const FormatOptions& options = {});
/// The status table: run line, column header, one row per agent in the order given, a totals row.
std::vector<std::string> format_status_table(const protocol::WorldStatus& status);

/// What each live agent of `status` waits for, one line each by id: "agent 3 return_to_base, 0.371 m3 on board, at
/// (154.38, 127.62) m: no nearer the base (20.6 m) for 2510 steps" ("(nothing said)" when it said nothing).
std::vector<std::string> format_waiting(const protocol::WorldStatus& status);

/// The agents of `status` in id order (the world sends them so; sorting keeps columns and tables stable whatever
/// arrives).
std::vector<const protocol::AgentStatus*> agents_by_id(const protocol::WorldStatus& status);
/// The name of an event's kind ("deposited", ...), or "kind N" for a kind this monitor does not know (a newer world).
std::string event_kind(protocol::EventKind kind);
/// `text` with every byte outside printable ASCII replaced by '?'.
std::string printable(const std::string& text);
/// `line` cut to `width` columns, ending in "..." when cut; unchanged when it fits or `width` is 0.
std::string fit_width(const std::string& line, int width);

}  // namespace marsala::monitor
