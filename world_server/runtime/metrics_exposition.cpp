#include "marsala/world_server/runtime/metrics_exposition.hpp"

#include <fmt/format.h>

#include <cmath>
#include <utility>

namespace marsala::world_server {
namespace {

/// A sample value as the text format writes it: shortest round-trip decimals, NaN, +Inf, -Inf.
std::string sample_value(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
  return fmt::format("{}", v);
}

/// A label value with backslash, double quote and line feed escaped.
std::string escaped(const std::string& value) {
  std::string out;
  for (const char c : value) {
    if (c == '\\' || c == '"') out += '\\';
    out += c == '\n' ? std::string("\\n") : std::string(1, c);
  }
  return out;
}

/// The text being written, family by family.
class Exposition {
 public:
  void family(const char* name, const char* type, const char* help) {
    text_ += fmt::format("# HELP {} {}\n# TYPE {} {}\n", name, help, name, type);
  }
  void sample(const std::string& name, const std::string& labels, const std::string& value) {
    text_ += labels.empty() ? fmt::format("{} {}\n", name, value) : fmt::format("{}{{{}}} {}\n", name, labels, value);
  }
  void sample(const std::string& name, double value) { sample(name, "", sample_value(value)); }
  void sample(const std::string& name, std::uint64_t value) { sample(name, "", fmt::format("{}", value)); }
  /// One family with one sample.
  template <typename T>
  void single(const char* name, const char* type, const char* help, T value) {
    family(name, type, help);
    sample(name, value);
  }
  void histogram(const char* name, const char* help, const DurationHistogram& h) {
    family(name, "histogram", help);
    std::uint64_t cumulative = 0;
    for (std::size_t i = 0; i < h.bucket_counts().size(); ++i) {
      cumulative += h.bucket_counts()[i];
      const std::string le = i < h.upper_bounds_s().size() ? sample_value(h.upper_bounds_s()[i]) : "+Inf";
      sample(fmt::format("{}_bucket", name), fmt::format("le=\"{}\"", le), fmt::format("{}", cumulative));
    }
    sample(fmt::format("{}_sum", name), h.sum_s());
    sample(fmt::format("{}_count", name), h.count());
  }
  /// One family with a sample per agent slot, labelled agent="<id>".
  template <typename F>
  void per_agent(const char* name, const char* type, const char* help, const MetricsSnapshot& s, F value_of) {
    family(name, type, help);
    for (const AgentMetrics& a : s.agents) sample(name, fmt::format("agent=\"{}\"", a.id), value_of(a));
  }
  std::string take() { return std::move(text_); }

 private:
  std::string text_;
};

/// The run state's label value: admitting, running, or the end reason.
std::string state_name(const MetricsSnapshot& s) {
  switch (s.phase) {
    case RunPhase::kAdmitting: return "admitting";
    case RunPhase::kRunning: return "running";
    case RunPhase::kOver: break;
  }
  return s.end_reason ? protocol::to_string(*s.end_reason) : std::string("over");
}

void run_families(Exposition& x, const MetricsSnapshot& s) {
  x.family("marsala_run_info", "gauge", "The run this world serves: its id, scenario and DDS vendor (always 1).");
  x.sample("marsala_run_info",
           fmt::format("run_id=\"{}\",scenario=\"{}\",dds=\"{}\"", escaped(s.run_id), escaped(s.scenario),
                       escaped(s.dds)),
           "1");
  x.family("marsala_run_state", "gauge",
           "1 for the state the run is in: admitting, running, or the end reason once it is over; 0 for the others.");
  const std::string now = state_name(s);
  for (const char* state : {"admitting", "running", "completed", "max_steps", "no_live_agents", "signal", "stalled"})
    x.sample("marsala_run_state", fmt::format("state=\"{}\"", state), now == state ? "1" : "0");
  x.single("marsala_steps_total", "counter", "Steps the world applied (summary.json steps).", s.steps);
  x.histogram("marsala_step_duration_seconds",
              "Wall time of each step this process ran: frames out, requests in, applied, recorded.", s.step_seconds);
  x.histogram("marsala_step_world_duration_seconds",
              "The world's own part of each step: its wall time less the time it waited for requests.",
              s.step_world_seconds);
  const double share = s.step_seconds.sum_s() > 0.0 ? s.step_world_seconds.sum_s() / s.step_seconds.sum_s() : 0.0;
  x.single("marsala_step_world_share_ratio", "gauge",
           "The world's own share of the steps this process ran: the sum of their world parts over their wall time.",
           share);
}

void agent_count_families(Exposition& x, const MetricsSnapshot& s) {
  x.single("marsala_agents_expected", "gauge", "Agent slots of the team (--agents).", std::uint64_t{s.agents_expected});
  x.single("marsala_agents_admitted", "gauge", "Agent slots admitted (summary.json admitted).",
           std::uint64_t{s.agents_admitted});
  x.single("marsala_agents_live", "gauge", "Agents admitted and not dropped.", std::uint64_t{s.agents_live});
  x.single("marsala_agents_connected", "gauge", "Live agents whose request writer is alive.",
           std::uint64_t{s.agents_connected});
  x.single("marsala_agents_dropped", "gauge", "Agents dropped and not taken back (summary.json dropped).",
           std::uint64_t{s.agents_dropped});
}

void request_families(Exposition& x, const MetricsSnapshot& s) {
  x.single("marsala_deadline_misses_total", "counter",
           "Steps a live agent sent no request for before the deadline (summary.json missed_deadlines).",
           s.deadline_misses);
  x.single("marsala_rejected_requests_total", "counter",
           "Requests rejected and charged to an agent (summary.json rejected_requests).", s.rejected_requests);
  x.single("marsala_unattributed_rejections_total", "counter",
           "Rejected requests that carried no admitted identity, charged to no agent.", s.unattributed_rejections);
  x.family("marsala_rejections_total", "counter",
           "Requests this world process rejected, by reason: identity, future_step, duplicate, or the validation "
           "rule (envelope, motion, deposition, refill).");
  for (std::size_t i = 0; i < kRejectionReasons; ++i)
    x.sample("marsala_rejections_total", fmt::format("reason=\"{}\"", to_string(static_cast<RejectionReason>(i))),
             fmt::format("{}", s.rejections_by_reason[i]));
  x.single("marsala_surplus_requests_total", "counter",
           "Requests beyond 8 per partition and step, counted and never applied.", s.surplus_requests);
  x.single("marsala_progress_ratio", "gauge", "The run's progress towards completion, 0 to 1.", s.progress);
  x.single("marsala_deposited_volume_m3_total", "counter", "Material deposited by the whole team [m^3].",
           s.deposited_m3);
}

void agent_families(Exposition& x, const MetricsSnapshot& s) {
  x.per_agent("marsala_agent_alive", "gauge", "1 while the agent is admitted and not dropped.", s,
              [](const AgentMetrics& a) { return a.alive ? "1" : "0"; });
  x.per_agent("marsala_agent_connected", "gauge", "1 while the agent is live and its request writer alive.", s,
              [](const AgentMetrics& a) { return a.connected ? "1" : "0"; });
  x.per_agent("marsala_agent_requests_accepted_total", "counter", "The agent's requests accepted.", s,
              [](const AgentMetrics& a) { return fmt::format("{}", a.accepted); });
  x.per_agent("marsala_agent_requests_rejected_total", "counter", "The agent's requests rejected.", s,
              [](const AgentMetrics& a) { return fmt::format("{}", a.rejected); });
  x.per_agent("marsala_agent_deadline_misses_total", "counter", "The agent's missed deadlines.", s,
              [](const AgentMetrics& a) { return fmt::format("{}", a.missed); });
  x.per_agent("marsala_agent_deposited_volume_m3_total", "counter", "Material the agent deposited [m^3].", s,
              [](const AgentMetrics& a) { return sample_value(a.deposited_m3); });
  x.per_agent("marsala_agent_material_m3", "gauge", "Material on board the agent [m^3].", s,
              [](const AgentMetrics& a) { return sample_value(a.material_m3); });
}

}  // namespace

std::string render_metrics(const MetricsSnapshot& snapshot) {
  Exposition x;
  run_families(x, snapshot);
  agent_count_families(x, snapshot);
  request_families(x, snapshot);
  agent_families(x, snapshot);
  return x.take();
}

std::string render_process_metrics(const ProcessMetrics& process) {
  Exposition x;
  x.single("process_cpu_seconds_total", "counter", "Total user and system CPU time spent in seconds.",
           process.cpu_seconds);
  x.single("process_resident_memory_bytes", "gauge", "Resident memory size in bytes.", process.resident_memory_bytes);
  x.single("process_start_time_seconds", "gauge", "Start time of the process since unix epoch in seconds.",
           process.start_time_seconds);
  return x.take();
}

}  // namespace marsala::world_server
