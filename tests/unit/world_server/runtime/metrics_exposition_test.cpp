#include "marsala/world_server/runtime/metrics_exposition.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

namespace marsala::world_server {
namespace {

/// A finished run of one agent, with numbers that are exact in binary (so their text is known by hand).
MetricsSnapshot finished_run() {
  MetricsSnapshot s;
  s.run_id = "ramp-d7";
  s.scenario = "a \"quoted\" \\ name\nsecond line";
  s.dds = "inprocess";
  s.phase = RunPhase::kOver;
  s.end_reason = protocol::EndReason::kCompleted;
  s.steps = 3;
  s.step_seconds = DurationHistogram({0.25, 1.0});
  for (double t : {0.25, 0.25, 0.5}) s.step_seconds.observe(t);
  s.step_world_seconds = DurationHistogram({0.25, 1.0});
  for (double t : {0.125, 0.0625, 0.0625}) s.step_world_seconds.observe(t);
  s.agents_expected = s.agents_admitted = s.agents_live = s.agents_connected = 1;
  s.rejected_requests = 1;
  s.unattributed_rejections = 2;
  s.surplus_requests = 5;
  s.rejections_by_reason[static_cast<std::size_t>(RejectionReason::kIdentity)] = 2;
  s.rejections_by_reason[static_cast<std::size_t>(RejectionReason::kMotion)] = 1;
  s.progress = 1.0;
  s.deposited_m3 = 0.125;
  AgentMetrics a;
  a.id = 1;
  a.admitted = a.alive = a.connected = true;
  a.accepted = 3;
  a.rejected = 1;
  a.deposited_m3 = 0.125;
  a.material_m3 = 0.375;
  s.agents.push_back(a);
  return s;
}

// Written by hand from the Prometheus text format (version 0.0.4) and docs/runtime.md#metrics.
const char* const kExpected = R"(# HELP marsala_run_info The run this world serves: its id, scenario and DDS vendor (always 1).
# TYPE marsala_run_info gauge
marsala_run_info{run_id="ramp-d7",scenario="a \"quoted\" \\ name\nsecond line",dds="inprocess"} 1
# HELP marsala_run_state 1 for the state the run is in: admitting, running, or the end reason once it is over; 0 for the others.
# TYPE marsala_run_state gauge
marsala_run_state{state="admitting"} 0
marsala_run_state{state="running"} 0
marsala_run_state{state="completed"} 1
marsala_run_state{state="max_steps"} 0
marsala_run_state{state="no_live_agents"} 0
marsala_run_state{state="signal"} 0
marsala_run_state{state="stalled"} 0
# HELP marsala_steps_total Steps the world applied (summary.json steps).
# TYPE marsala_steps_total counter
marsala_steps_total 3
# HELP marsala_step_duration_seconds Wall time of each step this process ran: frames out, requests in, applied, recorded.
# TYPE marsala_step_duration_seconds histogram
marsala_step_duration_seconds_bucket{le="0.25"} 2
marsala_step_duration_seconds_bucket{le="1"} 3
marsala_step_duration_seconds_bucket{le="+Inf"} 3
marsala_step_duration_seconds_sum 1
marsala_step_duration_seconds_count 3
# HELP marsala_step_world_duration_seconds The world's own part of each step: its wall time less the time it waited for requests.
# TYPE marsala_step_world_duration_seconds histogram
marsala_step_world_duration_seconds_bucket{le="0.25"} 3
marsala_step_world_duration_seconds_bucket{le="1"} 3
marsala_step_world_duration_seconds_bucket{le="+Inf"} 3
marsala_step_world_duration_seconds_sum 0.25
marsala_step_world_duration_seconds_count 3
# HELP marsala_step_world_share_ratio The world's own share of the steps this process ran: the sum of their world parts over their wall time.
# TYPE marsala_step_world_share_ratio gauge
marsala_step_world_share_ratio 0.25
# HELP marsala_agents_expected Agent slots of the team (--agents).
# TYPE marsala_agents_expected gauge
marsala_agents_expected 1
# HELP marsala_agents_admitted Agent slots admitted (summary.json admitted).
# TYPE marsala_agents_admitted gauge
marsala_agents_admitted 1
# HELP marsala_agents_live Agents admitted and not dropped.
# TYPE marsala_agents_live gauge
marsala_agents_live 1
# HELP marsala_agents_connected Live agents whose request writer is alive.
# TYPE marsala_agents_connected gauge
marsala_agents_connected 1
# HELP marsala_agents_dropped Agents dropped and not taken back (summary.json dropped).
# TYPE marsala_agents_dropped gauge
marsala_agents_dropped 0
# HELP marsala_deadline_misses_total Steps a live agent sent no request for before the deadline (summary.json missed_deadlines).
# TYPE marsala_deadline_misses_total counter
marsala_deadline_misses_total 0
# HELP marsala_rejected_requests_total Requests rejected and charged to an agent (summary.json rejected_requests).
# TYPE marsala_rejected_requests_total counter
marsala_rejected_requests_total 1
# HELP marsala_unattributed_rejections_total Rejected requests that carried no admitted identity, charged to no agent.
# TYPE marsala_unattributed_rejections_total counter
marsala_unattributed_rejections_total 2
# HELP marsala_rejections_total Requests this world process rejected, by reason: identity, future_step, duplicate, or the validation rule (envelope, motion, deposition, refill).
# TYPE marsala_rejections_total counter
marsala_rejections_total{reason="identity"} 2
marsala_rejections_total{reason="future_step"} 0
marsala_rejections_total{reason="duplicate"} 0
marsala_rejections_total{reason="envelope"} 0
marsala_rejections_total{reason="motion"} 1
marsala_rejections_total{reason="deposition"} 0
marsala_rejections_total{reason="refill"} 0
# HELP marsala_surplus_requests_total Requests beyond 8 per partition and step, counted and never applied.
# TYPE marsala_surplus_requests_total counter
marsala_surplus_requests_total 5
# HELP marsala_progress_ratio The run's progress towards completion, 0 to 1.
# TYPE marsala_progress_ratio gauge
marsala_progress_ratio 1
# HELP marsala_deposited_volume_m3_total Material deposited by the whole team [m^3].
# TYPE marsala_deposited_volume_m3_total counter
marsala_deposited_volume_m3_total 0.125
# HELP marsala_agent_alive 1 while the agent is admitted and not dropped.
# TYPE marsala_agent_alive gauge
marsala_agent_alive{agent="1"} 1
# HELP marsala_agent_connected 1 while the agent is live and its request writer alive.
# TYPE marsala_agent_connected gauge
marsala_agent_connected{agent="1"} 1
# HELP marsala_agent_requests_accepted_total The agent's requests accepted.
# TYPE marsala_agent_requests_accepted_total counter
marsala_agent_requests_accepted_total{agent="1"} 3
# HELP marsala_agent_requests_rejected_total The agent's requests rejected.
# TYPE marsala_agent_requests_rejected_total counter
marsala_agent_requests_rejected_total{agent="1"} 1
# HELP marsala_agent_deadline_misses_total The agent's missed deadlines.
# TYPE marsala_agent_deadline_misses_total counter
marsala_agent_deadline_misses_total{agent="1"} 0
# HELP marsala_agent_deposited_volume_m3_total Material the agent deposited [m^3].
# TYPE marsala_agent_deposited_volume_m3_total counter
marsala_agent_deposited_volume_m3_total{agent="1"} 0.125
# HELP marsala_agent_material_m3 Material on board the agent [m^3].
# TYPE marsala_agent_material_m3 gauge
marsala_agent_material_m3{agent="1"} 0.375
)";

TEST(MetricsExposition, RendersTheHandWrittenExposition) { EXPECT_EQ(render_metrics(finished_run()), kExpected); }

std::string line_of(const std::string& text, const std::string& start) {
  const auto at = text.find("\n" + start);
  if (at == std::string::npos) return "";
  return text.substr(at + 1, text.find('\n', at + 1) - at - 1);
}

TEST(MetricsExposition, StatesBeforeTheEnd) {
  MetricsSnapshot s;
  EXPECT_EQ(line_of(render_metrics(s), "marsala_run_state{state=\"admitting\"}"),
            "marsala_run_state{state=\"admitting\"} 1");
  EXPECT_EQ(line_of(render_metrics(s), "marsala_step_world_share_ratio "), "marsala_step_world_share_ratio 0");
  s.phase = RunPhase::kRunning;
  EXPECT_EQ(line_of(render_metrics(s), "marsala_run_state{state=\"running\"}"), "marsala_run_state{state=\"running\"} 1");
  s.phase = RunPhase::kOver;
  s.end_reason = protocol::EndReason::kStalled;
  EXPECT_EQ(line_of(render_metrics(s), "marsala_run_state{state=\"stalled\"}"), "marsala_run_state{state=\"stalled\"} 1");
  EXPECT_EQ(line_of(render_metrics(s), "marsala_run_state{state=\"running\"}"), "marsala_run_state{state=\"running\"} 0");
}

TEST(MetricsExposition, WritesNaNAndInfinitiesAsPrometheusReadsThem) {
  MetricsSnapshot s;
  s.progress = std::numeric_limits<double>::quiet_NaN();
  s.deposited_m3 = std::numeric_limits<double>::infinity();
  const std::string text = render_metrics(s);
  EXPECT_EQ(line_of(text, "marsala_progress_ratio "), "marsala_progress_ratio NaN");
  EXPECT_EQ(line_of(text, "marsala_deposited_volume_m3_total "), "marsala_deposited_volume_m3_total +Inf");
}

TEST(MetricsExposition, ProcessFamiliesAreThoseOfPrometheusClients) {
  EXPECT_EQ(render_process_metrics({12.5, 4096.0, 1795828000.25}),
            "# HELP process_cpu_seconds_total Total user and system CPU time spent in seconds.\n"
            "# TYPE process_cpu_seconds_total counter\n"
            "process_cpu_seconds_total 12.5\n"
            "# HELP process_resident_memory_bytes Resident memory size in bytes.\n"
            "# TYPE process_resident_memory_bytes gauge\n"
            "process_resident_memory_bytes 4096\n"
            "# HELP process_start_time_seconds Start time of the process since unix epoch in seconds.\n"
            "# TYPE process_start_time_seconds gauge\n"
            "process_start_time_seconds 1795828000.25\n");
}

// Prometheus's own checker (promtool, Debian's prometheus package) reads the text without a problem; skipped where
// it is not installed.
TEST(MetricsExposition, PromtoolFindsNoProblem) {
  if (std::system("command -v promtool >/dev/null 2>&1") != 0) GTEST_SKIP() << "promtool is not installed";
  MetricsSnapshot s = finished_run();
  s.scenario = "ramp";  // promtool flags nothing in label values; the escapes are checked above
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("marsala_metrics_" + std::to_string(::getpid()) + ".prom");
  std::ofstream(file) << render_metrics(s) << render_process_metrics({1.5, 1e6, 1795828000.0});
  const std::string command = "promtool check metrics < " + file.string() + " > " + file.string() + ".out 2>&1";
  const int rc = std::system(command.c_str());
  std::ifstream report(file.string() + ".out");
  const std::string said((std::istreambuf_iterator<char>(report)), std::istreambuf_iterator<char>());
  std::filesystem::remove(file);
  std::filesystem::remove(file.string() + ".out");
  EXPECT_EQ(rc, 0) << said;
  EXPECT_EQ(said, "");
}

}  // namespace
}  // namespace marsala::world_server
