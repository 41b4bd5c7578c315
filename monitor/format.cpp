#include "marsala/monitor/format.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <utility>

namespace marsala::monitor {
namespace {

std::string trim_right(std::string line) {
  line.erase(line.find_last_not_of(' ') + 1);
  return line;
}

std::string cut(const std::string& text, int width) {
  return text.substr(0, static_cast<std::size_t>(std::max(width, 0)));
}

/// The team's slots: the world's team size, or the agents it lists when it does not say [count].
std::size_t team_size(const protocol::WorldStatus& status) {
  return std::max<std::size_t>(status.team_size, status.agents.size());
}

std::size_t count_alive(const protocol::WorldStatus& status) {
  return static_cast<std::size_t>(
      std::count_if(status.agents.begin(), status.agents.end(), [](const auto& a) { return a.alive; }));
}

std::size_t count_at_goal(const protocol::WorldStatus& status) {
  return static_cast<std::size_t>(
      std::count_if(status.agents.begin(), status.agents.end(), [](const auto& a) { return a.alive && a.at_goal; }));
}

std::string state_of(const protocol::AgentStatus& agent) { return agent.state.empty() ? "?" : printable(agent.state); }

/// One agent's column text, at most `text_width` characters.
std::string agent_column(const protocol::AgentStatus& agent, int text_width) {
  if (!agent.alive) return "--";
  if (agent.at_goal) return cut(state_of(agent), text_width - 1) + "*";
  return cut(state_of(agent), text_width);
}

/// "build 9, refill 3": live agents per state, most frequent first, ties by name.
std::string states_summary(const protocol::WorldStatus& status) {
  std::map<std::string, int> counts;
  for (const protocol::AgentStatus& a : status.agents)
    if (a.alive) ++counts[state_of(a)];
  if (counts.empty()) return "no live agents";
  std::vector<std::pair<std::string, int>> sorted(counts.begin(), counts.end());
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string text;
  for (const auto& [state, count] : sorted) text += fmt::format("{}{} {}", text.empty() ? "" : ", ", state, count);
  return text;
}

std::string run_outcome(const protocol::WorldStatus& status) {
  if (status.admitting) return "admitting";
  if (status.running) return "running";
  return status.completed ? "completed" : "stopped";
}

const char* yes_no(bool value) { return value ? "yes" : "no"; }

/// " | missing 2 of 3 slots: 2 dropped, 3 never admitted" for the slots of the team not in the run (dropped, or never
/// admitted: ids up to the team size the world did not list); empty when none.
std::string missing_slots(const protocol::WorldStatus& status) {
  const std::size_t team = team_size(status);
  std::vector<std::string> missing;
  std::vector<bool> listed(team + 1, false);
  for (const protocol::AgentStatus* a : agents_by_id(status)) {
    if (a->agent_id <= team) listed[a->agent_id] = true;
    if (!a->alive) missing.push_back(fmt::format("{} dropped", a->agent_id));
  }
  for (std::size_t id = 1; id <= team; ++id)
    if (!listed[id]) missing.push_back(fmt::format("{} never admitted", id));
  if (missing.empty()) return "";
  return fmt::format(" | missing {} of {} slots: {}", missing.size(), team, fmt::join(missing, ", "));
}

}  // namespace

std::vector<const protocol::AgentStatus*> agents_by_id(const protocol::WorldStatus& status) {
  std::vector<const protocol::AgentStatus*> agents;
  for (const protocol::AgentStatus& a : status.agents) agents.push_back(&a);
  std::stable_sort(agents.begin(), agents.end(), [](auto* a, auto* b) { return a->agent_id < b->agent_id; });
  return agents;
}

std::string event_kind(protocol::EventKind kind) {
  const auto value = static_cast<unsigned>(kind);
  return value <= static_cast<unsigned>(protocol::EventKind::kRunOver) ? protocol::to_string(kind)
                                                                       : fmt::format("kind {}", value);
}

std::string printable(const std::string& text) {
  std::string out = text;
  for (char& ch : out) {
    const auto byte = static_cast<unsigned char>(ch);
    if (byte < 0x20 || byte >= 0x7f) ch = '?';
  }
  return out;
}

std::string fit_width(const std::string& line, int width) {
  if (width <= 0 || line.size() <= static_cast<std::size_t>(width)) return line;
  if (width <= 3) return line.substr(0, static_cast<std::size_t>(width));
  return line.substr(0, static_cast<std::size_t>(width - 3)) + "...";
}

int agent_column_text_width(std::size_t agent_count, const FormatOptions& options) {
  if (agent_count == 0 || options.width <= 0) return kMaxAgentColumnText;
  const long long room = options.width - kStepPrefixWidth;
  const long long text = room / static_cast<long long>(agent_count) - 1;  // each column: ' ' + text
  if (text < kMinAgentColumnText) return 0;
  return static_cast<int>(std::min<long long>(text, kMaxAgentColumnText));
}

std::string format_step_header(const protocol::WorldStatus& status, const FormatOptions& options) {
  std::string line = fmt::format("{:>6} {:>5} {:>7} {:>8} {:>4} |", "step", "live", "mat[m3]", "dep[m3]", "prog");
  const int text_width = agent_column_text_width(status.agents.size(), options);
  if (status.agents.empty()) {
    line += " no agents";
  } else if (text_width == 0) {
    line += " live agents by state";
  } else {
    for (const protocol::AgentStatus* a : agents_by_id(status))
      line += fmt::format(" {:<{}}", a->agent_id, text_width);
  }
  return fit_width(trim_right(line), options.width);
}

std::string format_step_line(const protocol::WorldStatus& status, const FormatOptions& options) {
  double material_m3 = 0.0;
  for (const protocol::AgentStatus& a : status.agents)
    if (a.alive) material_m3 += a.material_m3;
  const std::string live = fmt::format("{}/{}", count_alive(status), team_size(status));
  std::string line = fmt::format("{:>6} {:>5} {:7.2f} {:8.3f} {:3.0f}% |", status.step, live, material_m3,
                                 status.deposited_volume_m3, 100.0 * status.progress);
  const int text_width = agent_column_text_width(status.agents.size(), options);
  if (status.agents.empty()) {
    line += " no agents";
  } else if (text_width == 0) {
    line += fmt::format(" {}", states_summary(status));
  } else {
    for (const protocol::AgentStatus* a : agents_by_id(status))
      line += fmt::format(" {:<{}}", agent_column(*a, text_width), text_width);
  }
  return fit_width(trim_right(line), options.width);
}

std::string format_run_summary(const protocol::WorldStatus& status) {
  unsigned long long accepted = 0, rejected = 0, missed = 0;
  for (const protocol::AgentStatus& a : status.agents) {
    accepted += a.accepted;
    rejected += a.rejected;
    missed += a.missed;
  }
  const std::string progress =
      status.progress_detail.empty()
          ? std::string()
          : fmt::format(" | progress {:.1f}%: {}", 100.0 * status.progress, printable(status.progress_detail));
  return fmt::format(
      "run {} {} at step {} ({:.1f} s) | live {}/{}, at goal {}{} | dep {:.3f} m3 | acc {} rej {} miss {}{}",
      printable(status.run_id), run_outcome(status), status.step, status.wall_seconds, count_alive(status),
      team_size(status), count_at_goal(status), missing_slots(status),
      status.deposited_volume_m3, accepted, rejected, missed, progress);
}

std::vector<std::string> format_waiting(const protocol::WorldStatus& status) {
  std::vector<std::string> lines;
  for (const protocol::AgentStatus* a : agents_by_id(status))
    if (a->alive)
      lines.push_back(fmt::format("agent {} {}, {:.3f} m3 on board, at ({:.2f}, {:.2f}) m: {}", a->agent_id,
                                  state_of(*a), a->material_m3, a->x_m, a->y_m,
                                  a->waiting_for.empty() ? std::string("(nothing said)") : printable(a->waiting_for)));
  return lines;
}

std::string format_event(const protocol::WorldEvent& event, const FormatOptions& options) {
  const std::string who = event.agent_id == 0 ? std::string("world") : fmt::format("agent {}", event.agent_id);
  const std::string volume =
      event.kind == protocol::EventKind::kDeposited ? fmt::format(" {:.6g} m3", event.volume_m3) : std::string();
  const std::string detail = event.detail.empty() ? std::string() : fmt::format(" {}", printable(event.detail));
  const std::string line =
      fmt::format("{:>6} > {:<8} {:<9}{}{}", event.step, who, event_kind(event.kind), volume, detail);
  return fit_width(trim_right(line), options.width);
}

std::vector<std::string> format_status_table(const protocol::WorldStatus& status) {
  std::vector<std::string> lines;
  const std::string detail =
      status.progress_detail.empty() ? std::string() : fmt::format("  ({})", printable(status.progress_detail));
  lines.push_back(fmt::format("run {}  scenario {}  step {}  wall {:.1f} s  {}  progress {:.1f}%  deposited {:.4f} m3{}",
                              printable(status.run_id), printable(status.scenario), status.step, status.wall_seconds,
                              run_outcome(status), 100.0 * status.progress, status.deposited_volume_m3, detail));
  lines.push_back(trim_right(fmt::format("{:>3} {:<12} {:<11} {:>8} {:>8} {:>7} {:>7} {:>7} {:>5} {:>4} {:>4} {:<5} {:<4}",
                                         "id", "name", "state", "x[m]", "y[m]", "z[m]", "mat[m3]", "dep[m3]", "acc",
                                         "rej", "miss", "alive", "goal")));
  double material_m3 = 0.0, deposited_m3 = 0.0;
  unsigned long long accepted = 0, rejected = 0, missed = 0;
  for (const protocol::AgentStatus* a : agents_by_id(status)) {
    lines.push_back(trim_right(fmt::format(
        "{:>3} {:<12} {:<11} {:8.2f} {:8.2f} {:7.3f} {:7.4f} {:7.4f} {:>5} {:>4} {:>4} {:<5} {:<4}", a->agent_id,
        cut(printable(a->name), 12), cut(state_of(*a), 11), a->x_m, a->y_m, a->z_m, a->material_m3, a->deposited_m3,
        a->accepted, a->rejected, a->missed, yes_no(a->alive), yes_no(a->at_goal))));
    if (a->alive && !a->waiting_for.empty())
      lines.push_back(fmt::format("    waiting for: {}", printable(a->waiting_for)));
    material_m3 += a->material_m3;
    deposited_m3 += a->deposited_m3;
    accepted += a->accepted;
    rejected += a->rejected;
    missed += a->missed;
  }
  const std::string agents = fmt::format("{} agent{}", status.agents.size(), status.agents.size() == 1 ? "" : "s");
  lines.push_back(trim_right(fmt::format(
      "{:>3} {:<12} {:<11} {:>8} {:>8} {:>7} {:7.4f} {:7.4f} {:>5} {:>4} {:>4} {:<5} {:<4}", "", "total", agents, "", "",
      "", material_m3, deposited_m3, accepted, rejected, missed, count_alive(status), count_at_goal(status))));
  return lines;
}

}  // namespace marsala::monitor
