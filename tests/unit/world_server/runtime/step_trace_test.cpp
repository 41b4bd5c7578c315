#include "marsala/world_server/runtime/step_trace.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <unistd.h>

#include "marsala/core/error.hpp"
#include "unit/world_server/world_cli_fixture.hpp"
#include "unit/world_server/world_fixtures.hpp"

namespace marsala::world_server {
namespace {

namespace fs = std::filesystem;
using Clock = StepTimes::Clock;
using std::chrono::microseconds;

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(StepTrace, ASpanIsOneCompleteEvent) {
  EXPECT_EQ(trace_event_json({kWorldTrack, "apply", 1500.25, 12.5, 7}),
            R"({"name":"apply","cat":"world","ph":"X","ts":1500.250,"dur":12.500,"pid":1,"tid":0,"args":{"step":7}})");
  EXPECT_EQ(trace_event_json({3, "answer", 0.0, 0.001, 0}),
            R"({"name":"answer","cat":"agent","ph":"X","ts":0.000,"dur":0.001,"pid":1,"tid":3,"args":{"step":0}})");
}

// Hand-made phase ends 100 us after the origin: frames 10 us, wait 50 us (agent 2 answers after 20, agent 1 after 45,
// agent 3 misses), apply 5, record 15, status 8.
TEST(StepTrace, APhasesTileItsStepAndEachAgentWaitsFromTheFrames) {
  const Clock::time_point origin{};
  StepTimes t;
  t.step = 4;
  t.start = origin + microseconds(100);
  t.frames_out = t.start + microseconds(10);
  t.collected = t.frames_out + microseconds(50);
  t.applied = t.collected + microseconds(5);
  t.recorded = t.applied + microseconds(15);
  t.published = t.recorded + microseconds(8);
  t.answers = {{2, t.frames_out + microseconds(20)}, {1, t.frames_out + microseconds(45)}};
  t.missed = {3};
  std::map<std::pair<std::uint32_t, std::string>, std::pair<double, double>> got;
  for (const TraceSpan& s : step_spans(t, origin)) {
    EXPECT_EQ(s.step, 4u);
    got[{s.track, s.name}] = {s.start_us, s.duration_us};
  }
  const std::map<std::pair<std::uint32_t, std::string>, std::pair<double, double>> expected{
      {{0, "step"}, {100, 80}},    {{0, "frames"}, {100, 10}}, {{0, "collect"}, {110, 50}},
      {{0, "apply"}, {160, 5}},    {{0, "record"}, {165, 15}}, {{0, "status"}, {180, 8}},
      {{2, "answer"}, {110, 20}},  {{1, "answer"}, {110, 45}}, {{3, "missed"}, {110, 50}}};
  EXPECT_EQ(got, expected);
}

// An agent's reported decision lies inside its answer and ends where the answer was read; one longer than the answer
// (its clock is not the world's) is cut to it; an agent that reports none gets no "decide".
TEST(StepTrace, AnAgentsDecisionEndsWhereItsAnswerWasRead) {
  const Clock::time_point origin{};
  StepTimes t;
  t.step = 9;
  t.start = origin;
  t.frames_out = t.start + microseconds(10);
  t.collected = t.applied = t.recorded = t.published = t.frames_out + microseconds(60);
  t.answers = {{1, t.frames_out + microseconds(30), 12, 9},
               {2, t.frames_out + microseconds(40), 500, 480},
               {3, t.frames_out + microseconds(50), 0, 0}};
  std::map<std::pair<std::uint32_t, std::string>, std::pair<double, double>> got;
  std::map<std::uint32_t, double> cpu;
  for (const TraceSpan& s : step_spans(t, origin)) {
    if (s.track == kWorldTrack) continue;
    got[{s.track, s.name}] = {s.start_us, s.duration_us};
    if (s.name == "decide") cpu[s.track] = s.cpu_us;
  }
  const std::map<std::pair<std::uint32_t, std::string>, std::pair<double, double>> expected{
      {{1, "answer"}, {10, 30}}, {{1, "decide"}, {28, 12}}, {{2, "answer"}, {10, 40}},
      {{2, "decide"}, {10, 40}}, {{3, "answer"}, {10, 50}}};
  EXPECT_EQ(got, expected);
  EXPECT_EQ(cpu, (std::map<std::uint32_t, double>{{1, 9.0}, {2, 480.0}}));
  EXPECT_EQ(trace_event_json({1, "decide", 28, 12, 9, 9.0}),
            R"({"name":"decide","cat":"agent","ph":"X","ts":28.000,"dur":12.000,"pid":1,"tid":1,"args":{"step":9,"cpu_us":9}})");
}

TEST(StepTrace, WritesTheFileOnlyWhenFinished) {
  const fs::path dir = fs::temp_directory_path() / ("marsala_trace_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / "trace.json";
  {
    StepTrace trace(path.string(), Clock::now());
    EXPECT_TRUE(fs::exists(path.string() + ".tmp"));
  }
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));  // a run that failed leaves nothing
  EXPECT_FALSE(fs::exists(path));
  {
    StepTrace trace(path.string(), Clock::now());
    trace.name_tracks(2);
    StepTimes t;
    t.start = t.frames_out = t.collected = t.applied = t.recorded = t.published = Clock::now();
    trace.step(t);
    trace.finish();
  }
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  const nlohmann::json doc = read_json(path);
  EXPECT_EQ(doc["traceEvents"].size(), 2u + 2u + 6u);  // process and world names, two agents' names, six spans
  fs::remove_all(dir);
  EXPECT_THROW(StepTrace((dir / "no" / "such" / "trace.json").string(), Clock::now()), IoError);
}

/// marsala-world's command line beside a walking fake agent, as WorldCliTest runs it.
class StepTraceRun : public testing::WorldCliFixture {};

// A real lockstep (in process): every span of a step lies within it, the phases add up to the step, and the steps'
// times are summary.json's (its median within 5 %).
TEST_F(StepTraceRun, TheTraceOfARunNestsAndMatchesTheSummary) {
  const std::string scenario = write("small.pbtxt", testing::small_scenario_text());
  const fs::path out = dir_ / "out", trace = dir_ / "trace.json";
  const int rc = run_beside_walker(
      71, {"--scenario", scenario, "--out", out.string(), "--max-steps", "12", "--trace", trace.string()});
  ASSERT_TRUE(rc == 0 || rc == 3) << rc << ": " << err_.str();  // the walker may reach the goal first
  const nlohmann::json summary = read_json(out / "summary.json");
  const auto steps = summary["steps"].get<std::size_t>();
  ASSERT_GE(steps, 5u);

  std::map<std::uint64_t, std::map<std::string, std::pair<double, double>>> world_spans;  // step -> name -> (ts, dur)
  std::map<std::uint64_t, std::pair<double, double>> answers;
  const nlohmann::json doc = read_json(trace);
  for (const nlohmann::json& e : doc["traceEvents"]) {
    if (e["ph"] != "X") continue;
    const std::pair<double, double> span{e["ts"].get<double>(), e["dur"].get<double>()};
    if (e["tid"].get<int>() == 0)
      world_spans[e["args"]["step"].get<std::uint64_t>()][e["name"].get<std::string>()] = span;
    else if (e["name"] == "answer")
      answers[e["args"]["step"].get<std::uint64_t>()] = span;
  }
  ASSERT_EQ(world_spans.size(), steps);
  ASSERT_EQ(answers.size(), steps);
  std::vector<double> step_ms;
  for (const auto& [step, spans] : world_spans) {
    const auto [ts, dur] = spans.at("step");
    double phases = 0.0;
    for (const char* name : {"frames", "collect", "apply", "record"}) {
      const auto [child_ts, child_dur] = spans.at(name);
      EXPECT_GE(child_ts, ts - 0.001) << name << " of step " << step;
      EXPECT_LE(child_ts + child_dur, ts + dur + 0.002) << name << " of step " << step;
      phases += child_dur;
    }
    EXPECT_NEAR(phases, dur, 0.005) << "step " << step;
    const auto [answer_ts, answer_dur] = answers.at(step);
    EXPECT_GE(answer_ts, spans.at("collect").first - 0.001);
    EXPECT_LE(answer_ts + answer_dur, spans.at("collect").first + spans.at("collect").second + 0.002);
    step_ms.push_back(dur / 1000.0);
  }
  std::sort(step_ms.begin(), step_ms.end());
  const double median_ms = summary["step_wall_median_ms"].get<double>();
  const double traced_ms = step_ms[step_ms.size() / 2];  // the summary's median: nearest rank, the upper middle
  EXPECT_NEAR(traced_ms, median_ms, 0.05 * median_ms) << "traced " << traced_ms << " ms, summary " << median_ms;
}

// A trace file that cannot be written is refused with one line naming it, exit 2, before the run's folder is made.
TEST_F(StepTraceRun, AnUnwritableTraceIsRefusedBeforeAnythingIsWritten) {
  const std::string scenario = write("small.pbtxt", testing::small_scenario_text());
  const fs::path out = dir_ / "out", trace = dir_ / "no" / "such" / "trace.json";
  EXPECT_EQ(run({"--scenario", scenario, "--out", out.string(), "--dds", "inprocess", "--trace", trace.string()}), 2);
  const std::string said = err_.str();
  EXPECT_EQ(said.rfind("marsala-world: error: --trace " + trace.string() + ": cannot write", 0), 0u) << said;
  EXPECT_EQ(std::count(said.begin(), said.end(), '\n'), 1) << said;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace marsala::world_server
