// A run's progress for people: tail's pacing (--every, --interval), the step rate and ETA from the world's clock,
// the progress line and `marsala-monitor progress` in place and as lines, and the account of a finished run.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/monitor/follow.hpp"
#include "marsala/monitor/monitor_cli.hpp"
#include "marsala/monitor/progress.hpp"
#include "marsala/monitor/run_report.hpp"
#include "unit/monitor/fake_world.hpp"

namespace marsala::monitor {
namespace {

using namespace std::chrono_literals;
using test_support::FakeWorld;
using Clock = std::chrono::steady_clock;

protocol::WorldStatus status(std::uint64_t step, double wall_s, double progress, bool running = true) {
  protocol::WorldStatus s;
  s.run_id = "p";
  s.scenario = "path";
  s.step = step;
  s.wall_seconds = wall_s;
  s.progress = progress;
  s.running = running;
  s.completed = !running && progress >= 1.0;
  s.progress_detail = running ? "3.00 of 4.00 m3 of MARS gap left on the route" : "the payload's path is navigable";
  protocol::AgentStatus a;
  a.agent_id = 1;
  a.name = "builder-1";
  a.state = "build";
  s.agents.push_back(a);
  return s;
}

std::vector<std::uint64_t> taken(LinePacing pacing, const std::vector<std::uint64_t>& steps,
                                 std::chrono::milliseconds spacing = 0ms) {
  std::vector<std::uint64_t> out;
  Clock::time_point t{};
  for (std::uint64_t s : steps) {
    if (pacing.take(s, t)) out.push_back(s);
    t += spacing;
  }
  return out;
}

TEST(LinePacing, EveryStepByDefaultOrOncePerMultipleOfN) {
  EXPECT_EQ(taken(LinePacing(), {0, 1, 2, 3}), (std::vector<std::uint64_t>{0, 1, 2, 3}));
  std::vector<std::uint64_t> all;
  for (std::uint64_t s = 0; s <= 35; ++s) all.push_back(s);
  EXPECT_EQ(taken(LinePacing(10), all), (std::vector<std::uint64_t>{0, 10, 20, 30}));
  // A monitor that joins late or misses statuses prints the first it sees and then one per multiple crossed.
  EXPECT_EQ(taken(LinePacing(10), {3, 7, 12, 25, 26, 41}), (std::vector<std::uint64_t>{3, 12, 25, 41}));
}

TEST(LinePacing, AtMostOneLinePerIntervalAndBothLimitsTogether) {
  // A status every 100 ms, a line at most every 250 ms: steps 0, 3, 6, 9.
  EXPECT_EQ(taken(LinePacing(0, 250ms), {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, 100ms),
            (std::vector<std::uint64_t>{0, 3, 6, 9}));
  // Every 2 steps and at most every 250 ms: step 2 crosses a multiple of 2 but comes too soon after step 0; step 3
  // is past both limits, and so on.
  EXPECT_EQ(taken(LinePacing(2, 250ms), {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, 100ms),
            (std::vector<std::uint64_t>{0, 3, 6, 9}));
  EXPECT_EQ(taken(LinePacing(5, 250ms), {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 100ms),
            (std::vector<std::uint64_t>{0, 5, 10}));
}

TEST(ProgressMeter, RateAndEtaFollowTheWorldsClock) {
  ProgressMeter meter(30.0);
  EXPECT_EQ(meter.steps_per_s(), 0.0);
  EXPECT_FALSE(meter.eta_s().has_value());
  // 200 steps/s, 5 % of the way per second: at 40 % after 8 s, 12 s to go.
  for (int i = 0; i <= 1600; ++i) meter.add(i / 200.0, static_cast<std::uint64_t>(i), 0.05 * (i / 200.0));
  EXPECT_NEAR(meter.steps_per_s(), 200.0, 1e-6);
  ASSERT_TRUE(meter.eta_s().has_value());
  EXPECT_NEAR(*meter.eta_s(), 12.0, 1e-6);
  // A late, older status changes nothing.
  meter.add(1.0, 200, 0.05);
  EXPECT_NEAR(*meter.eta_s(), 12.0, 1e-6);
}

TEST(ProgressMeter, UsesOnlyTheRecentWindowAndForgetsAfterTheClockRestarts) {
  ProgressMeter meter(10.0);
  // 50 s at 100 steps/s with no progress, then 10 s at 300 steps/s with progress 0.02 per second.
  for (int i = 0; i <= 500; ++i) meter.add(i / 10.0, static_cast<std::uint64_t>(10 * i), 0.0);
  for (int i = 1; i <= 100; ++i) meter.add(50.0 + i / 10.0, 5000u + 30u * i, 0.002 * i);
  EXPECT_NEAR(meter.steps_per_s(), 300.0, 10.0);  // the window's first sample lies within 0.2 s of 10 s back
  ASSERT_TRUE(meter.eta_s().has_value());
  EXPECT_NEAR(*meter.eta_s(), (1.0 - 0.2) / 0.02, 1.0);
  // No progress in the window: no estimate.
  ProgressMeter flat(10.0);
  for (int i = 0; i <= 100; ++i) flat.add(i / 10.0, static_cast<std::uint64_t>(i), 0.5);
  EXPECT_FALSE(flat.eta_s().has_value());
  // A resumed world's clock starts again at 0: the meter starts afresh instead of seeing time run backwards.
  meter.add(0.0, 8000, 0.3);
  EXPECT_EQ(meter.steps_per_s(), 0.0);
  meter.add(1.0, 8100, 0.31);
  EXPECT_NEAR(meter.steps_per_s(), 100.0, 1e-9);
}

TEST(ProgressLine, RunningAdmittingAndOver) {
  EXPECT_EQ(format_duration(std::nullopt), "-");
  EXPECT_EQ(format_duration(0.4), "< 1 s");
  EXPECT_EQ(format_duration(4.4), "4 s");
  EXPECT_EQ(format_duration(125.0), "2 min 05 s");
  EXPECT_EQ(format_duration(3725.0), "1 h 02 min");

  ProgressMeter meter;
  meter.add(0.0, 0, 0.0);
  meter.add(2.0, 800, 0.25);
  EXPECT_EQ(format_progress_line(status(800, 2.0, 0.25), meter),
            "step 800 | 25.0 % | 400 steps/s | ETA 6 s | 3.00 of 4.00 m3 of MARS gap left on the route");
  EXPECT_EQ(format_progress_line(status(800, 2.0, 0.25), meter, 48), "step 800 | 25.0 % | 400 steps/s | ETA 6 s | 3...");
  protocol::WorldStatus admitting = status(0, 0.0, 0.0);
  admitting.admitting = true;
  EXPECT_EQ(format_progress_line(admitting, meter), "admitting agents: 1 admitted");
  EXPECT_EQ(format_progress_line(status(1460, 3.6, 1.0, false), meter),
            "completed at step 1460 in 3.6 s | 100.0 % | the payload's path is navigable");
}

/// Runs `marsala-monitor ARGS` in-process on a thread.
std::future<std::pair<int, std::string>> monitor(std::vector<std::string> args) {
  return std::async(std::launch::async, [args] {
    std::vector<std::string> full = args;
    full.insert(full.begin(), "marsala-monitor");
    std::vector<const char*> argv;
    for (const std::string& a : full) argv.push_back(a.c_str());
    std::ostringstream out, err;
    const int code = run_monitor_cli(static_cast<int>(argv.size()), argv.data(), out, err, StopSource{});
    return std::make_pair(code, out.str() + err.str());
  });
}

TEST(ProgressCommand, RewritesOneLineInPlaceAndEndsItWithTheRun) {
  FakeWorld world(90);
  auto run = monitor({"progress", "--dds", "inprocess", "--domain", "90", "--in-place", "--interval", "0.001",
                      "--timeout", "10"});
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  world.publish(status(100, 1.0, 0.1));
  std::this_thread::sleep_for(50ms);
  world.publish(status(200, 2.0, 0.2));
  std::this_thread::sleep_for(50ms);
  world.publish(status(300, 3.0, 1.0, false));
  ASSERT_EQ(run.wait_for(10s), std::future_status::ready);
  const auto [code, out] = run.get();
  EXPECT_EQ(code, 0) << out;
  // Every update starts with a carriage return and erases the rest of the line; only the last ends it. (Which
  // statuses got their own update depends on the threads' timing; the shape does not.)
  EXPECT_EQ(out.rfind("\r", 0), 0u) << out;
  for (std::size_t at = out.find('\r', 1); at != std::string::npos; at = out.find('\r', at + 1))
    EXPECT_EQ(out.substr(at - 3, 3), "\x1b[K") << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  const std::string last = "\rcompleted at step 300 in 3.0 s | 100.0 % | the payload's path is navigable\x1b[K\n";
  EXPECT_EQ(out.substr(out.size() - last.size()), last) << out;
}

TEST(ProgressCommand, PrintsWholeLinesWhenNotInPlace) {
  FakeWorld world(91);
  auto run = monitor({"progress", "--dds", "inprocess", "--domain", "91", "--interval", "0.001", "--timeout", "10"});
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  world.publish(status(100, 1.0, 0.1));
  std::this_thread::sleep_for(50ms);
  world.publish(status(300, 3.0, 1.0, false));
  ASSERT_EQ(run.wait_for(10s), std::future_status::ready);
  const auto [code, out] = run.get();
  EXPECT_EQ(code, 0) << out;
  EXPECT_EQ(out.find('\r'), std::string::npos) << out;
  EXPECT_EQ(out.find('\x1b'), std::string::npos) << out;
  EXPECT_EQ(out.find("step 100 | 10.0 % |"), out.rfind("step ", 0)) << out;  // the first line, if it got one
  EXPECT_NE(out.find("completed at step 300 in 3.0 s | 100.0 % | the payload's path is navigable\n"), std::string::npos)
      << out;
}

TEST(TailPacing, EveryNStepsAndTheLastLine) {
  FakeWorld world(92);
  auto run = monitor({"tail", "--dds", "inprocess", "--domain", "92", "--every", "5", "--timeout", "10"});
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  for (std::uint64_t step = 0; step < 12; ++step) world.publish(status(step, 0.1 * step, 0.05 * step));
  world.publish(status(12, 1.2, 1.0, false));
  ASSERT_EQ(run.wait_for(10s), std::future_status::ready);
  const auto [code, out] = run.get();
  EXPECT_EQ(code, 0) << out;
  std::vector<std::string> steps;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);)
    if (line.size() > 6 && line.find(" | ") != std::string::npos && line.find("step") == std::string::npos &&
        line.rfind("run ", 0) != 0)
      steps.push_back(line.substr(0, 6));
  EXPECT_EQ(steps, (std::vector<std::string>{"     0", "     5", "    10", "    12"})) << out;
  EXPECT_NE(out.find("| progress 100.0%: the payload's path is navigable"), std::string::npos) << out;
}

TEST(MonitorOptions, BadPacingAndProgressOptionsExitTwo) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"tail", "--every", "0"},
           {"tail", "--every", "x"},
           {"tail", "--interval", "0"},
           {"tail", "--interval", "-1"},
           {"progress", "--in-place", "--lines"},
           {"progress", "--interval", "0"},
           {"progress", "--width", "-3"},
           {"summary"},
       }) {
    auto run = monitor(args);
    const auto [code, out] = run.get();
    EXPECT_EQ(code, 2) << args[0] << " " << (args.size() > 1 ? args[1] : "") << ": " << out;
    EXPECT_NE(out.find("(run with --help for usage)"), std::string::npos) << out;
  }
}

class RunReport : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("marsala_run_report_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ / "logs");
    for (const char* name : {"final_zoom.png", "final.png", "final_3d.png", "events.log", "run.log"})
      std::ofstream(dir_ / name) << "x";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write_summary(const std::string& json) { std::ofstream(dir_ / "summary.json") << json; }
  std::filesystem::path dir_;
};

TEST_F(RunReport, ACompletedPathRun) {
  write_summary(R"({"scenario": "path_generated", "completed": true, "end_reason": "completed", "steps": 1460,
    "wall_seconds": 3.56, "admit_seconds": 0.42, "deposited_volume_m3": 21.241, "agents": 5, "admitted": 5,
    "dropped": 0, "completion": "payload_path", "path_found": true, "path_length_m": 26.18, "progress": 1,
    "progress_detail": "the payload's path is navigable", "seed": "1", "some_future_field": 3})");
  const std::string d = dir_.string();
  EXPECT_EQ(run_report(d),
            "path_generated completed after 1460 steps in 3.6 s (admission 0.4 s)\n"
            "  agents 5 (5 admitted, 0 dropped), 21.241 m3 deposited, payload path 26.2 m\n"
            "  progress 100.0 %: the payload's path is navigable\n"
            "  pictures in " + d + ": final.png, final_3d.png, final_zoom.png\n"
            "  everything else in " + d + ": events.log, logs/, run.log, summary.json\n");
}

TEST_F(RunReport, ACompletedRunShortOfSlotsNamesThem) {
  write_summary(R"({"scenario": "ramp", "completed": true, "end_reason": "completed", "steps": 410,
    "agents": 3, "admitted": 2, "dropped": 1, "completion": "agents_at_goal", "progress": 1,
    "slots_missing": 2, "missing_agents": [2, 3]})");
  const std::string report = run_report(dir_.string());
  EXPECT_NE(report.find("\n  short of 2 of 3 slots at the end (never admitted, or dropped and not back): agents 2, 3\n"),
            std::string::npos)
      << report;
  write_summary(R"({"scenario": "ramp", "completed": true, "agents": 3, "admitted": 3, "slots_missing": 0})");
  EXPECT_EQ(run_report(dir_.string()).find("short of"), std::string::npos);
}

TEST_F(RunReport, AForkNamesItsParentTheSlotsThatLeftAtKAndItsSet) {
  write_summary(R"({"scenario": "ramp", "completed": true, "end_reason": "completed", "steps": 127,
    "agents": 3, "admitted": 3, "dropped": 1, "completion": "agents_at_goal", "progress": 1, "slots_missing": 0,
    "fork": {"parent": "out/parent", "at_step": "100", "parent_agents": 3, "agents": 2, "left_agents": [3],
             "overrides": ["stall_steps=50", "goal.min_height_m=0.2"]}})");
  const std::string report = run_report(dir_.string());
  EXPECT_NE(report.find("\n  fork of out/parent at step 100: team 3 -> 2 (agent 3 left at step 100 by choice: not "
                        "missing), --set stall_steps=50 goal.min_height_m=0.2\n"),
            std::string::npos)
      << report;
  EXPECT_EQ(report.find("short of"), std::string::npos) << report;
  write_summary(R"({"scenario": "ramp", "completed": true, "agents": 3, "admitted": 3,
    "fork": {"parent": "p", "at_step": "7", "parent_agents": 3, "agents": 3}})");
  EXPECT_NE(run_report(dir_.string()).find("\n  fork of p at step 7: team 3 -> 3\n"), std::string::npos);
  write_summary(R"({"scenario": "ramp", "completed": true, "agents": 5, "admitted": 4, "slots_missing": 1,
    "fork": {"parent": "p", "at_step": "7", "parent_agents": 3, "agents": 5, "joined_agents": [4]}})");
  EXPECT_NE(run_report(dir_.string()).find("\n  fork of p at step 7: team 3 -> 5 (1 of 2 late slots joined at step 7: "
                                           "agent 4)\n"),
            std::string::npos)
      << run_report(dir_.string());
}

TEST_F(RunReport, SaysWhatLandedOutsideTheConstructionBand) {
  write_summary(R"({"scenario": "path_gale", "completed": true, "end_reason": "completed", "steps": 3500,
    "agents": 1, "admitted": 1, "deposited_volume_m3": 30.361, "completion": "payload_path", "path_found": true,
    "path_length_m": 40.0, "progress": 1, "construction_band_width_m": 3, "deposited_outside_band_m3": 4.5})");
  EXPECT_NE(run_report(dir_.string()).find(", payload path 40.0 m, 4.500 m3 outside the 3.0 m construction band\n"),
            std::string::npos)
      << run_report(dir_.string());
}

TEST_F(RunReport, PrintsTheMaterialScore) {
  write_summary(R"({"scenario": "ramp", "completed": true, "end_reason": "completed", "steps": 298, "agents": 3,
    "admitted": 3, "deposited_volume_m3": 12.0, "completion": "agents_at_goal", "progress": 1,
    "material": {"deposited_m3": 12.0, "needed_m3": 10.0, "ratio": 1.2, "off_band_m3": 0.5}})");
  EXPECT_NE(run_report(dir_.string())
                .find("\n  material 12.000 of 10.000 m3 needed: ratio 1.200 (1 = the exact MARS need), 0.500 m3 off "
                      "the band\n"),
            std::string::npos)
      << run_report(dir_.string());
  write_summary(R"({"scenario": "ramp", "completed": true, "agents": 3, "admitted": 3})");  // an older summary
  EXPECT_EQ(run_report(dir_.string()).find("material"), std::string::npos);
}

TEST_F(RunReport, SaysWhereTheTimeLapseIs) {
  write_summary(R"({"scenario": "ramp", "completed": true, "end_reason": "completed", "steps": 275,
    "wall_seconds": 2.0, "agents": 3, "admitted": 3, "completion": "agents_at_goal", "progress": 1})");
  std::filesystem::create_directories(dir_ / "frames");
  for (const char* name : {"frame_000000.png", "frame_000100.png", "frame_000275.png", "timelapse.mp4"})
    std::ofstream(dir_ / "frames" / name) << "x";
  const std::string report = run_report(dir_.string());
  EXPECT_NE(report.find("\n  time-lapse in " + (dir_ / "frames").string() + ": 3 frames, timelapse.mp4\n"),
            std::string::npos)
      << report;
  std::filesystem::remove(dir_ / "frames" / "timelapse.mp4");
  EXPECT_NE(run_report(dir_.string()).find(": 3 frames\n"), std::string::npos);
}

TEST_F(RunReport, ARunThatDidNotCompleteSaysWhy) {
  write_summary(R"json({"scenario": "site_prep", "completed": false, "end_reason": "max_steps", "steps": 500,
    "wall_seconds": 2.0, "deposited_volume_m3": 10.5, "agents": 11, "admitted": 11, "dropped": 1,
    "missed_deadlines": 4, "completion": "level_site", "site_level_fraction": 0.873, "progress": 0.873,
    "progress_detail": "site 87.3 % level (100.0 % needed)"})json");
  const std::string report = run_report(dir_.string());
  EXPECT_EQ(report.substr(0, report.find('\n')),
            "site_prep did not complete: it reached its step limit (max_steps), after 500 steps in 2.0 s (admission "
            "0.0 s)");
  EXPECT_NE(report.find("agents 11 (11 admitted, 1 dropped), 10.500 m3 deposited, site 87.3 % level\n"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("4 missed deadlines, 0 rejected requests"), std::string::npos) << report;
  EXPECT_NE(report.find("progress 87.3 %: site 87.3 % level (100.0 % needed)\n"), std::string::npos) << report;
}

TEST_F(RunReport, AStalledRunTellsWhatEachRobotWaitedFor) {
  write_summary(R"json({"scenario": "path_gale", "completed": false, "end_reason": "stalled", "steps": 6621,
    "wall_seconds": 70.0, "agents": 2, "admitted": 2, "completion": "payload_path", "progress": 0.035,
    "stall": {"stall_steps": 2000, "quiet_since_step": 4621, "best_progress": 0.035, "agents": [
      {"agent_id": 1, "state": "return_to_base", "material_m3": 0.947, "x_m": 151.125, "y_m": 127.375, "z_m": 17.68,
       "waiting_for": "no nearer the base (18.9 m) for 2565 steps: robots 2 at 1.2 m close by"},
      {"agent_id": 2, "state": "hold\u0007", "material_m3": 1, "x_m": 152.375, "y_m": 127.375, "z_m": 17.45}]}})json");
  const std::string report = run_report(dir_.string());
  EXPECT_EQ(report.substr(0, report.find('\n')),
            "path_gale did not complete: it stopped making progress (stalled), after 6621 steps in 70.0 s (admission "
            "0.0 s)");
  EXPECT_NE(
      report.find("  stalled: no rise of the progress and no terrain change for 2000 steps, since step 4621; "
                  "what each robot waited for:\n"
                  "    agent 1 return_to_base, 0.947 m3 on board, at (151.12, 127.38, 17.68) m: no nearer the base "
                  "(18.9 m) for 2565 steps: robots 2 at 1.2 m close by\n"
                  "    agent 2 hold?, 1.000 m3 on board, at (152.38, 127.38, 17.45) m: (nothing said)\n"),
      std::string::npos)
      << report;
}

TEST_F(RunReport, AMissingOrBrokenSummaryIsAnErrorNamingTheFile) {
  EXPECT_THROW(run_report(dir_.string()), IoError);
  write_summary("{\"steps\": \"many\"");
  try {
    run_report(dir_.string());
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("summary.json"), std::string::npos) << e.what();
  }
  // Through the command line: exit 1, one line.
  auto run = monitor({"summary", dir_.string()});
  const auto [code, out] = run.get();
  EXPECT_EQ(code, 1);
  EXPECT_EQ(out.rfind("marsala-monitor: ", 0), 0u) << out;
}

}  // namespace
}  // namespace marsala::monitor
