// The live view: roles from behaviour states, the state document the page reads, and serve's usage errors (a bad
// port, a port in use, conflicting options: exit 2 naming what). The page itself is tested in a browser by
// tests/integration/live_view_test.sh.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/monitor/live_model.hpp"
#include "marsala/monitor/monitor_cli.hpp"
#include "marsala/monitor/serve.hpp"
#include "support/busy_port.hpp"

namespace marsala::monitor {
namespace {

using nlohmann::json;
using Clock = LiveModel::Clock;

protocol::WorldStatus status_at(std::uint64_t step, double wall_s) {
  protocol::WorldStatus s;
  s.run_id = "r1";
  s.scenario = "ramp";
  s.step = step;
  s.wall_seconds = wall_s;
  s.progress = 0.25;
  s.progress_detail = "3.00 of 4.00 m3 of MARS gap left on the route\x1b";
  s.world_id = 7;
  for (std::uint32_t id : {2u, 1u}) {
    protocol::AgentStatus a;
    a.agent_id = id;
    a.name = "husky-" + std::to_string(id);
    a.state = id == 1 ? "build" : "follow";
    a.x_m = id;
    a.y_m = 2.0 * id;
    s.agents.push_back(a);
  }
  return s;
}

TEST(RobotRole, FromTheBehaviourStates) {
  for (const char* s : {"survey", "advance", "build", "retreat", "active"})
    EXPECT_EQ(role_of(s, true), RobotRole::kActive) << s;
  for (const char* s : {"follow", "hold", "back_off"}) EXPECT_EQ(role_of(s, true), RobotRole::kFollowing) << s;
  EXPECT_EQ(role_of("return_to_base", true), RobotRole::kReturning);
  EXPECT_EQ(role_of("done", true), RobotRole::kDone);
  EXPECT_EQ(role_of("at_goal", true), RobotRole::kDone);
  EXPECT_EQ(role_of("", true), RobotRole::kWaiting);
  EXPECT_EQ(role_of("dance", true), RobotRole::kWaiting);
  EXPECT_EQ(role_of("build", false), RobotRole::kDropped);
  EXPECT_EQ(to_string(RobotRole::kActive), "active");
  EXPECT_EQ(to_string(RobotRole::kFollowing), "following");
  EXPECT_EQ(to_string(RobotRole::kReturning), "returning");
  EXPECT_EQ(to_string(RobotRole::kDone), "done");
  EXPECT_EQ(to_string(RobotRole::kDropped), "dropped");
  EXPECT_EQ(to_string(RobotRole::kWaiting), "waiting");
}

TEST(LiveModel, StepsPerSecondOverTheWorldsWallTime) {
  LiveModel model("test");
  const Clock::time_point t0 = Clock::now();
  EXPECT_EQ(model.steps_per_second(), 0.0);
  model.on_status(status_at(10, 1.0), t0);
  EXPECT_EQ(model.steps_per_second(), 0.0);  // one status: no rate yet
  model.on_status(status_at(60, 1.5), t0);
  EXPECT_DOUBLE_EQ(model.steps_per_second(), 100.0);
  // Older than the 2 s window: forgotten, the rate follows the recent pace.
  for (int k = 1; k <= 40; ++k) model.on_status(status_at(60 + 10 * k, 1.5 + 0.1 * k), t0);
  EXPECT_NEAR(model.steps_per_second(), 100.0, 1e-6);
  model.on_status(status_at(500, 10.0), t0);  // 40 steps in 4.5 s after a pause
  EXPECT_NEAR(model.steps_per_second(), 40.0 / 4.5, 1e-9);
}

TEST(LiveModel, StateDocumentForThePage) {
  LiveModel model("DDS domain 9 (cyclone)");
  const Clock::time_point t0 = Clock::now();
  model.on_status(status_at(5, 0.5), t0);
  protocol::WorldEvent e;
  e.step = 5;
  e.agent_id = 1;
  e.kind = protocol::EventKind::kDeposited;
  e.volume_m3 = 0.01;
  e.detail = "2 cells\x1b[31m";
  model.on_event(e);
  const json j = json::parse(model.state_json(t0 + std::chrono::seconds(2)));
  EXPECT_EQ(j["source"], "DDS domain 9 (cyclone)");
  EXPECT_EQ(j["run"]["step"], 5);
  EXPECT_EQ(j["run"]["phase"], "running");
  EXPECT_EQ(j["run"]["scenario"], "ramp");
  EXPECT_EQ(j["run"]["progress_detail"], "3.00 of 4.00 m3 of MARS gap left on the route?");
  EXPECT_NEAR(j["run"]["status_age_s"].get<double>(), 2.0, 1e-6);
  ASSERT_EQ(j["agents"].size(), 2u);
  EXPECT_EQ(j["agents"][0]["id"], 1);  // in id order
  EXPECT_EQ(j["agents"][0]["role"], "active");
  EXPECT_EQ(j["agents"][1]["role"], "following");
  ASSERT_EQ(j["events"].size(), 1u);
  EXPECT_EQ(j["events"][0]["kind"], "deposited");
  EXPECT_EQ(j["events"][0]["detail"], "2 cells?[31m");  // no control bytes from the wire reach the page
  EXPECT_TRUE(j["map"].is_null());
  EXPECT_EQ(j["palette"].size(), 12u);

  LiveMap map;
  map.geometry = GridGeometry{20, 30, 1.0, 2.0, 0.1};
  map.version = 3;
  LiveScene scene;
  scene.completion = "agents_at_goal";
  scene.goal = Rect{1, 2, 3, 4};
  scene.base = Position{5.5, 6.25};
  scene.targets.emplace_back(1, Position{2.5, 3.5});
  map.scene = scene;
  model.set_map(map);
  const json k = json::parse(model.state_json(t0));
  EXPECT_EQ(k["map"]["version"], 3);
  EXPECT_DOUBLE_EQ(k["map"]["width_m"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(k["map"]["height_m"].get<double>(), 2.0);
  EXPECT_EQ(k["map"]["scene"]["goal"], json::parse(R"({"x0": 1.0, "y0": 2.0, "x1": 3.0, "y1": 4.0})"));
  EXPECT_EQ(k["map"]["scene"]["base"]["x"], 5.5);
  EXPECT_EQ(k["map"]["scene"]["base"]["y"], 6.25);
  EXPECT_FALSE(k["map"]["scene"].contains("site"));
  EXPECT_EQ(k["map"]["scene"]["targets"][0]["id"], 1);
}

TEST(LiveModel, ANewRunStartsAfresh) {
  LiveModel model("test");
  const Clock::time_point t0 = Clock::now();
  model.on_status(status_at(100, 1.0), t0);
  model.on_status(status_at(200, 2.0), t0);
  model.on_event(protocol::WorldEvent{});
  protocol::WorldStatus other = status_at(3, 0.1);
  other.run_id = "r2";
  model.on_status(other, t0);
  EXPECT_EQ(model.status()->step, 3u);
  EXPECT_EQ(model.steps_per_second(), 0.0);
  // Within one run a late, older status never moves the view back.
  protocol::WorldStatus late = other;
  late.step = 2;
  model.on_status(late, t0);
  EXPECT_EQ(model.status()->step, 3u);
}

struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

Result run_cli(std::vector<std::string> args) {
  args.insert(args.begin(), "marsala-monitor");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  Result r;
  r.exit_code = run_monitor_cli(static_cast<int>(argv.size()), argv.data(), out, err, StopSource{});
  r.out = out.str();
  r.err = err.str();
  return r;
}

TEST(Serve, UsageErrorsExitTwoNamingWhat) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"serve", "--port", "0"}, "--port"},
      {{"serve", "--port", "65536"}, "--port"},
      {{"serve", "--port", "http"}, "--port"},
      {{"serve", "--frobnicate"}, "--frobnicate"},
      {{"serve", "--speed", "10"}, "--speed"},  // only with --replay
      {{"serve", "--replay", "a", "--run-dir", "b"}, "--replay"},
      {{"serve", "--replay", "/nonexistent/run"}, "/nonexistent/run"},
      {{"serve", "--bind", "localhost:80"}, "localhost:80"},
  };
  for (const auto& [args, named] : cases) {
    const Result r = run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args.back() << ": " << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
  }
}

TEST(Serve, APortInUseExitsTwoNamingIt) {
  marsala::testing::BusyPort busy;
  const std::string port = std::to_string(busy.port());
  const Result r = run_cli({"serve", "--port", port, "--dds", "inprocess"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("127.0.0.1 port " + port), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("in use"), std::string::npos) << r.err;
  ServeOptions o;
  o.port = busy.port();
  EXPECT_THROW(LiveServer{o}, ListenError);
  o.port = 0;
  EXPECT_THROW(LiveServer{o}, InvalidArgument);
}

}  // namespace
}  // namespace marsala::monitor
