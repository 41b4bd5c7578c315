#include "marsala/monitor/format.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <map>
#include <utility>

namespace marsala::monitor {
namespace {

[[gnu::format(printf, 1, 2)]] std::string printf_string(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int size = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string text(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
  if (size > 0) std::vsnprintf(text.data(), text.size() + 1, format, args);
  va_end(args);
  return text;
}

std::string trim_right(std::string line) {
  line.erase(line.find_last_not_of(' ') + 1);
  return line;
}

std::string pad_right(const std::string& text, int width) {
  return text.size() >= static_cast<std::size_t>(width) ? text : text + std::string(width - text.size(), ' ');
}

std::string cut(const std::string& text, int width) {
  return text.substr(0, static_cast<std::size_t>(std::max(width, 0)));
}

/// Agents in id order (the world sends them so; sorting keeps the columns stable whatever arrives).
std::vector<const protocol::AgentStatus*> by_id(const protocol::WorldStatus& status) {
  std::vector<const protocol::AgentStatus*> agents;
  for (const protocol::AgentStatus& a : status.agents) agents.push_back(&a);
  std::stable_sort(agents.begin(), agents.end(), [](auto* a, auto* b) { return a->agent_id < b->agent_id; });
  return agents;
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
  for (const auto& [state, count] : sorted) text += (text.empty() ? "" : ", ") + state + " " + std::to_string(count);
  return text;
}

std::string run_outcome(const protocol::WorldStatus& status) {
  if (status.admitting) return "admitting";
  if (status.running) return "running";
  return status.completed ? "completed" : "stopped";
}

const char* yes_no(bool value) { return value ? "yes" : "no"; }

}  // namespace

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
  std::string line = printf_string("%6s %5s %7s %8s %4s |", "step", "live", "mat[m3]", "dep[m3]", "prog");
  const int text_width = agent_column_text_width(status.agents.size(), options);
  if (status.agents.empty()) {
    line += " no agents";
  } else if (text_width == 0) {
    line += " live agents by state";
  } else {
    for (const protocol::AgentStatus* a : by_id(status))
      line += " " + pad_right(std::to_string(a->agent_id), text_width);
  }
  return fit_width(trim_right(line), options.width);
}

std::string format_step_line(const protocol::WorldStatus& status, const FormatOptions& options) {
  double material_m3 = 0.0;
  for (const protocol::AgentStatus& a : status.agents)
    if (a.alive) material_m3 += a.material_m3;
  const std::string live = std::to_string(count_alive(status)) + "/" + std::to_string(status.agents.size());
  std::string line = printf_string("%6llu %5s %7.2f %8.3f %3.0f%% |", static_cast<unsigned long long>(status.step),
                                   live.c_str(), material_m3, status.deposited_volume_m3, 100.0 * status.progress);
  const int text_width = agent_column_text_width(status.agents.size(), options);
  if (status.agents.empty()) {
    line += " no agents";
  } else if (text_width == 0) {
    line += " " + states_summary(status);
  } else {
    for (const protocol::AgentStatus* a : by_id(status))
      line += " " + pad_right(agent_column(*a, text_width), text_width);
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
  std::string line = printf_string(
      "run %s %s at step %llu (%.1f s) | live %zu/%zu, at goal %zu | dep %.3f m3 | acc %llu rej %llu "
      "miss %llu",
      printable(status.run_id).c_str(), run_outcome(status).c_str(), static_cast<unsigned long long>(status.step),
      status.wall_seconds, count_alive(status), status.agents.size(), count_at_goal(status), status.deposited_volume_m3,
      accepted, rejected, missed);
  if (!status.progress_detail.empty())
    line += printf_string(" | progress %.1f%%: %s", 100.0 * status.progress, printable(status.progress_detail).c_str());
  return line;
}

std::string format_event(const protocol::WorldEvent& event, const FormatOptions& options) {
  const std::string who = event.agent_id == 0 ? "world" : "agent " + std::to_string(event.agent_id);
  const auto kind_value = static_cast<unsigned>(event.kind);
  const std::string kind = kind_value <= static_cast<unsigned>(protocol::EventKind::kRunOver)
                               ? protocol::to_string(event.kind)
                               : "kind " + std::to_string(kind_value);
  std::string line =
      printf_string("%6llu > %-8s %-9s", static_cast<unsigned long long>(event.step), who.c_str(), kind.c_str());
  if (event.kind == protocol::EventKind::kDeposited) line += printf_string(" %.6g m3", event.volume_m3);
  if (!event.detail.empty()) line += " " + printable(event.detail);
  return fit_width(trim_right(line), options.width);
}

std::vector<std::string> format_status_table(const protocol::WorldStatus& status) {
  std::vector<std::string> lines;
  lines.push_back(printf_string("run %s  scenario %s  step %llu  wall %.1f s  %s  progress %.1f%%  deposited %.4f m3",
                                printable(status.run_id).c_str(), printable(status.scenario).c_str(),
                                static_cast<unsigned long long>(status.step), status.wall_seconds,
                                run_outcome(status).c_str(), 100.0 * status.progress, status.deposited_volume_m3));
  if (!status.progress_detail.empty()) lines.back() += "  (" + printable(status.progress_detail) + ")";
  lines.push_back(
      trim_right(printf_string("%3s %-12s %-11s %8s %8s %7s %7s %7s %5s %4s %4s %-5s %-4s", "id", "name", "state",
                               "x[m]", "y[m]", "z[m]", "mat[m3]", "dep[m3]", "acc", "rej", "miss", "alive", "goal")));
  double material_m3 = 0.0, deposited_m3 = 0.0;
  unsigned long long accepted = 0, rejected = 0, missed = 0;
  for (const protocol::AgentStatus* a : by_id(status)) {
    lines.push_back(trim_right(printf_string(
        "%3u %-12s %-11s %8.2f %8.2f %7.3f %7.4f %7.4f %5u %4u %4u %-5s %-4s", static_cast<unsigned>(a->agent_id),
        cut(printable(a->name), 12).c_str(), cut(state_of(*a), 11).c_str(), a->x_m, a->y_m, a->z_m, a->material_m3,
        a->deposited_m3, static_cast<unsigned>(a->accepted), static_cast<unsigned>(a->rejected),
        static_cast<unsigned>(a->missed), yes_no(a->alive), yes_no(a->at_goal))));
    material_m3 += a->material_m3;
    deposited_m3 += a->deposited_m3;
    accepted += a->accepted;
    rejected += a->rejected;
    missed += a->missed;
  }
  const std::string agents = std::to_string(status.agents.size()) + (status.agents.size() == 1 ? " agent" : " agents");
  lines.push_back(trim_right(printf_string("%3s %-12s %-11s %8s %8s %7s %7.4f %7.4f %5llu %4llu %4llu %-5zu %-4zu", "",
                                           "total", agents.c_str(), "", "", "", material_m3, deposited_m3, accepted,
                                           rejected, missed, count_alive(status), count_at_goal(status))));
  return lines;
}

}  // namespace marsala::monitor
