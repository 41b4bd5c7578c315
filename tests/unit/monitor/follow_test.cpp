// tail and status against the in-process bus, with the test playing the world server.
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <typeinfo>
#include <utility>
#include <vector>

#include "marsala/core/error.hpp"
#include "marsala/monitor/follow.hpp"
#include "unit/monitor/fake_world.hpp"

namespace marsala::monitor {
namespace {

using test_support::FakeWorld;

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

protocol::WorldStatus status(const std::string& run_id, std::uint64_t step, std::vector<std::uint32_t> ids = {1, 2}) {
  protocol::WorldStatus s;
  s.run_id = run_id;
  s.scenario = "ramp";
  s.step = step;
  s.deposited_volume_m3 = 0.000125 * static_cast<double>(step);
  for (std::uint32_t id : ids) {
    protocol::AgentStatus a;
    a.agent_id = id;
    a.name = "builder-" + std::to_string(id);
    a.state = step % 2 == 0 ? "build" : "refill";
    a.material_m3 = 1.0;
    s.agents.push_back(a);
  }
  return s;
}

protocol::WorldStatus final_status(const std::string& run_id, std::uint64_t step) {
  protocol::WorldStatus s = status(run_id, step);
  s.running = false;
  s.completed = true;
  s.progress = 1.0;
  for (auto& a : s.agents) a.at_goal = true;
  return s;
}

protocol::WorldEvent event(std::uint64_t step, std::uint32_t agent_id, protocol::EventKind kind,
                           const std::string& detail = "") {
  protocol::WorldEvent e;
  e.step = step;
  e.agent_id = agent_id;
  e.kind = kind;
  e.detail = detail;
  if (kind == protocol::EventKind::kDeposited) e.volume_m3 = 0.000125;
  return e;
}

std::string text(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs tail (or status) on its own thread with its own participant, as the CLI does.
class MonitorThread {
 public:
  MonitorThread(int domain_id, TailOptions options)
      : participant_(bus::make_participant({bus::Vendor::kInProcess, domain_id})), options_(std::move(options)) {
    future_ = std::async(std::launch::async, [this] { return run_tail(*participant_, options_, stop_, out_, err_); });
  }
  MonitorThread(int domain_id, StatusOptions options)
      : participant_(bus::make_participant({bus::Vendor::kInProcess, domain_id})) {
    future_ = std::async(std::launch::async,
                         [this, options] { return run_status(*participant_, options, stop_, out_, err_); });
  }
  ~MonitorThread() {
    stop_.request_stop();
    if (future_.valid()) future_.wait();
  }

  void stop() { stop_.request_stop(); }
  /// Waits for the monitor to return (at most 10 s: then it is stopped and the test fails).
  Result join() {
    if (future_.wait_for(10s) != std::future_status::ready) {
      ADD_FAILURE() << "the monitor did not return within 10 s";
      stop_.request_stop();
    }
    Result r;
    r.exit_code = future_.get();
    r.out = out_.str();
    r.err = err_.str();
    return r;
  }

 private:
  std::unique_ptr<bus::Participant> participant_;
  TailOptions options_;
  StopSource stop_;
  std::ostringstream out_;
  std::ostringstream err_;
  std::future<int> future_;
};

TailOptions tail_options(bool events) {
  TailOptions o;
  o.events = events;
  o.timeout = 10s;  // a safety net: every test ends well before
  return o;
}

TEST(Tail, PrintsEachStepAndItsEventsThenEndsWithTheRun) {
  FakeWorld world(61);
  MonitorThread tail(61, tail_options(true));
  ASSERT_TRUE(world.wait_for_monitor(1, 1));
  // The world publishes a step's events before its status; kRunOver comes after the final status.
  const auto e0 = event(0, 1, protocol::EventKind::kAdmitted);
  const auto e1 = event(1, 2, protocol::EventKind::kDeposited, "1 cell");
  const auto e2 = event(2, 1, protocol::EventKind::kAtGoal);
  const auto over = event(2, 0, protocol::EventKind::kRunOver, "completed");
  const auto s0 = status("r1", 0), s1 = status("r1", 1), s2 = final_status("r1", 2);
  world.publish(e0);
  world.publish(s0);
  world.publish(e1);
  world.publish(s1);
  world.publish(e2);
  world.publish(s2);
  world.publish(over);
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, text({format_event(e0), format_step_header(s0), format_step_line(s0), format_event(e1),
                         format_step_line(s1), format_event(e2), format_event(over), format_step_line(s2),
                         format_run_summary(s2)}));
  // Spot-check the lines themselves (format_test holds the full goldens).
  EXPECT_NE(r.out.find("     1   2/2    2.00    0.000   0% | refill      refill\n"), std::string::npos);
  EXPECT_NE(r.out.find("run r1 completed at step 2 (0.0 s) | live 2/2, at goal 2 |"), std::string::npos);
}

TEST(Tail, EventsOfAStepWaitForItsStatus) {
  // The events of step 2 go out while the status of step 1 is still on its way: a take of events can
  // hold the next step's events before its status. They print after the status of step 1.
  FakeWorld world(66);
  MonitorThread tail(66, tail_options(true));
  ASSERT_TRUE(world.wait_for_monitor(1, 1));
  const auto e1 = event(1, 2, protocol::EventKind::kDeposited, "1 cell");
  const auto e2 = event(2, 1, protocol::EventKind::kAtGoal);
  const auto over = event(2, 0, protocol::EventKind::kRunOver, "completed");
  const auto s0 = status("r6", 0), s1 = status("r6", 1), s2 = final_status("r6", 2);
  world.publish(s0);
  world.publish(e1);
  world.publish(e2);
  std::this_thread::sleep_for(300ms);  // the monitor takes s0, e1 and e2 before s1 exists
  world.publish(s1);
  world.publish(s2);
  world.publish(over);
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, text({format_step_header(s0), format_step_line(s0), format_event(e1), format_step_line(s1),
                         format_event(e2), format_event(over), format_step_line(s2), format_run_summary(s2)}));
}

TEST(Tail, ALateMonitorStartsAtTheLatestStatusAndSkipsEventsUnlessAsked) {
  FakeWorld world(62);
  world.publish(status("r2", 5));
  world.publish(status("r2", 6));
  MonitorThread tail(62, tail_options(false));
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  world.publish(event(6, 1, protocol::EventKind::kDeposited));
  world.publish(final_status("r2", 7));
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, text({format_step_header(status("r2", 6)), format_step_line(status("r2", 6)),
                         format_step_line(final_status("r2", 7)), format_run_summary(final_status("r2", 7))}));
}

TEST(Tail, HeaderAgainWhenTheTeamChangesAndNoRunOverEventIsNeeded) {
  FakeWorld world(63);
  TailOptions options = tail_options(true);
  options.drain = 50ms;  // the world here never sends kRunOver
  MonitorThread tail(63, options);
  ASSERT_TRUE(world.wait_for_monitor(1, 1));
  const auto a = status("r3", 1, {1, 2, 3}), b = status("r3", 2, {1, 2, 3}), c = status("r3", 3, {1, 3});
  protocol::WorldStatus end = status("r3", 4, {1, 3});
  end.running = false;
  for (const auto& s : {a, b, c, end}) world.publish(s);
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, text({format_step_header(a), format_step_line(a), format_step_line(b), format_step_header(c),
                         format_step_line(c), format_step_line(end), format_run_summary(end)}));
  EXPECT_NE(r.out.find("run r3 stopped at step 4"), std::string::npos);
}

TEST(Tail, WaitsBrieflyForTheEventsAfterTheFinalStatus) {
  FakeWorld world(60);
  MonitorThread tail(60, tail_options(true));  // drain: 0.5 s
  ASSERT_TRUE(world.wait_for_monitor(1, 1));
  const auto end = final_status("r0", 8);
  const auto over = event(8, 0, protocol::EventKind::kRunOver, "completed");
  world.publish(end);
  std::this_thread::sleep_for(100ms);  // the last event comes a little later
  world.publish(over);
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, text({format_event(over), format_step_header(end), format_step_line(end), format_run_summary(end)}));
}

TEST(Tail, StopRequestEndsCleanlyAfterPrintingWhatArrived) {
  FakeWorld world(64);
  MonitorThread tail(64, tail_options(false));
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  world.publish(status("r4", 3));  // delivered when write() returns, before the stop
  tail.stop();
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out, text({format_step_header(status("r4", 3)), format_step_line(status("r4", 3)),
                         "tail stopped after step 3 of run r4"}));
}

TEST(Tail, StopBeforeAnyStatus) {
  FakeWorld world(65);
  TailOptions options;  // no timeout: waits forever until stopped
  MonitorThread tail(65, options);
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  tail.stop();
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out, "tail stopped before any world status\n");
  EXPECT_EQ(r.err, "marsala-monitor: tailing domain 65 (inprocess); Ctrl-C stops\n");
}

TEST(Tail, TimesOutWithoutAWorld) {
  TailOptions options;
  options.timeout = 200ms;
  const auto start = Clock::now();
  MonitorThread tail(66, options);
  const Result r = tail.join();
  EXPECT_GE(Clock::now() - start, 200ms);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("marsala-monitor: no world status on domain 66 (inprocess) for 0.2 s\n"), std::string::npos)
      << r.err;
}

TEST(Tail, EndsWithALineAndExit3WhenTheWorldIsGone) {
  FakeWorld world(73);
  TailOptions options = tail_options(false);  // the 10 s timeout is only a safety net here
  options.gone_after = 300ms;
  MonitorThread tail(73, options);
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  world.publish(status("r5", 3));
  std::this_thread::sleep_for(500ms);  // longer than gone_after: a live writer keeps tail waiting
  const auto left = Clock::now();
  world.leave();  // its process dies: no final status will come
  const Result r = tail.join();
  EXPECT_GE(Clock::now() - left, 300ms);
  EXPECT_LT(Clock::now() - left, 5s);
  EXPECT_EQ(r.exit_code, kExitWorldGone);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.out, text({format_step_header(status("r5", 3)), format_step_line(status("r5", 3)),
                         "world gone: no live world status writer for 0.3 s (last: step 3 of run r5); tail ends"}));
  EXPECT_NE(r.err.find("marsala-monitor: the world is gone: no live world status writer on domain 73 (inprocess) for "
                       "0.3 s (last: step 3 of run r5)\n"),
            std::string::npos)
      << r.err;
}

TEST(Tail, AWorldBackWithinGoneAfterIsFollowedToTheEnd) {
  FakeWorld world(74);
  TailOptions options = tail_options(false);
  options.gone_after = 3s;
  MonitorThread tail(74, options);
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  world.publish(status("r6", 3));
  world.leave();  // paused: back within gone_after
  std::this_thread::sleep_for(300ms);
  world.join();
  world.publish(final_status("r6", 4));
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, text({format_step_header(status("r6", 3)), format_step_line(status("r6", 3)),
                         format_step_line(final_status("r6", 4)), format_run_summary(final_status("r6", 4))}));
}

TEST(Tail, ANeverSeenWorldIsNotGoneButTimesOut) {
  TailOptions options;
  options.timeout = 400ms;
  options.gone_after = 100ms;  // no run seen yet: only the timeout ends it
  MonitorThread tail(75, options);
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("no world status on domain 75 (inprocess) for 0.4 s"), std::string::npos) << r.err;
}

TEST(Tail, EachStatusRestartsTheTimeout) {
  FakeWorld world(67);
  TailOptions options;
  options.timeout = 800ms;
  MonitorThread tail(67, options);
  ASSERT_TRUE(world.wait_for_monitor(1, 0));
  // Four statuses 0.4 s apart span 1.2 s > the timeout: only a restarted timeout lets the last ones through.
  for (std::uint64_t step = 1; step <= 4; ++step) {
    if (step > 1) std::this_thread::sleep_for(400ms);
    world.publish(status("r7", step));
  }
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.out, text({format_step_header(status("r7", 1)), format_step_line(status("r7", 1)),
                         format_step_line(status("r7", 2)), format_step_line(status("r7", 3)),
                         format_step_line(status("r7", 4))}));
  EXPECT_NE(r.err.find("for 0.8 s (last: step 4 of run r7)"), std::string::npos) << r.err;
}

TEST(Tail, FollowsOneRunOnly) {
  FakeWorld world_a(68);
  TailOptions options = tail_options(false);
  options.run_id = "b";
  MonitorThread tail(68, options);
  ASSERT_TRUE(world_a.wait_for_monitor(1, 0));
  FakeWorld world_b(68);  // after the wait: its probes would count as the monitor's readers
  world_a.publish(status("a", 1));
  world_b.publish(status("b", 1));
  world_a.publish(final_status("a", 2));  // another run's end does not end this tail
  world_b.publish(final_status("b", 2));
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out, text({format_step_header(status("b", 1)), format_step_line(status("b", 1)),
                         format_step_line(final_status("b", 2)), format_run_summary(final_status("b", 2))}));
  EXPECT_NE(r.err.find("ignoring run 'a' (following 'b')"), std::string::npos) << r.err;
}

TEST(Tail, WithoutARunIdFollowsTheFirstRunSeen) {
  FakeWorld world_a(69);
  MonitorThread tail(69, tail_options(false));
  ASSERT_TRUE(world_a.wait_for_monitor(1, 0));
  FakeWorld world_b(69);
  world_a.publish(status("a", 1));
  world_b.publish(final_status("b", 1));  // another run's end does not end this tail
  world_a.publish(final_status("a", 2));
  const Result r = tail.join();
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out, text({format_step_header(status("a", 1)), format_step_line(status("a", 1)),
                         format_step_line(final_status("a", 2)), format_run_summary(final_status("a", 2))}));
  EXPECT_NE(r.err.find("ignoring run 'b' (following 'a')"), std::string::npos) << r.err;
}

TEST(Status, PrintsTheLatestTransientLocalStatusAtOnce) {
  FakeWorld world(70);
  world.publish(status("r8", 41));
  world.publish(status("r8", 42));
  StatusOptions options;
  options.timeout = 5s;
  const auto start = Clock::now();
  MonitorThread monitor(70, options);
  const Result r = monitor.join();
  EXPECT_LT(Clock::now() - start, 2s);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, text(format_status_table(status("r8", 42))));
}

TEST(Status, NoWorldServer) {
  StatusOptions options;
  options.timeout = 100ms;
  MonitorThread monitor(71, options);
  const Result r = monitor.join();
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "marsala-monitor: no world server on domain 71 (inprocess): no world status within 0.1 s\n");
}

/// A participant that hands out readers of an in-process participant and fails any writer request.
class ReadOnlySpy final : public bus::Participant {
 public:
  explicit ReadOnlySpy(int domain_id) : inner_(bus::make_participant({bus::Vendor::kInProcess, domain_id})) {}
  bus::Vendor vendor() const override { return inner_->vendor(); }
  int domain_id() const override { return inner_->domain_id(); }
  bus::WriterId id() const override { return inner_->id(); }

  int writers_requested = 0;
  std::vector<std::pair<std::string, bus::EndpointOptions>> readers;  ///< message type and options, in order

 protected:
  template <typename T>
  std::unique_ptr<bus::Writer<T>> refuse() {
    ++writers_requested;
    throw BusError("the monitor asked for a writer");
  }
  template <typename T>
  std::unique_ptr<bus::Reader<T>> reader(const bus::EndpointOptions& o) {
    readers.emplace_back(typeid(T).name(), o);
    return inner_->create_reader<T>(o);
  }

  // clang-format off
  std::unique_ptr<bus::Writer<protocol::AgentHello>> make_writer(bus::Tag<protocol::AgentHello>, const bus::EndpointOptions&) override { return refuse<protocol::AgentHello>(); }
  std::unique_ptr<bus::Writer<protocol::Admission>> make_writer(bus::Tag<protocol::Admission>, const bus::EndpointOptions&) override { return refuse<protocol::Admission>(); }
  std::unique_ptr<bus::Writer<protocol::SensorFrame>> make_writer(bus::Tag<protocol::SensorFrame>, const bus::EndpointOptions&) override { return refuse<protocol::SensorFrame>(); }
  std::unique_ptr<bus::Writer<protocol::ActionRequest>> make_writer(bus::Tag<protocol::ActionRequest>, const bus::EndpointOptions&) override { return refuse<protocol::ActionRequest>(); }
  std::unique_ptr<bus::Writer<protocol::WorldStatus>> make_writer(bus::Tag<protocol::WorldStatus>, const bus::EndpointOptions&) override { return refuse<protocol::WorldStatus>(); }
  std::unique_ptr<bus::Writer<protocol::WorldEvent>> make_writer(bus::Tag<protocol::WorldEvent>, const bus::EndpointOptions&) override { return refuse<protocol::WorldEvent>(); }
  std::unique_ptr<bus::Reader<protocol::AgentHello>> make_reader(bus::Tag<protocol::AgentHello>, const bus::EndpointOptions& o) override { return reader<protocol::AgentHello>(o); }
  std::unique_ptr<bus::Reader<protocol::Admission>> make_reader(bus::Tag<protocol::Admission>, const bus::EndpointOptions& o) override { return reader<protocol::Admission>(o); }
  std::unique_ptr<bus::Reader<protocol::SensorFrame>> make_reader(bus::Tag<protocol::SensorFrame>, const bus::EndpointOptions& o) override { return reader<protocol::SensorFrame>(o); }
  std::unique_ptr<bus::Reader<protocol::ActionRequest>> make_reader(bus::Tag<protocol::ActionRequest>, const bus::EndpointOptions& o) override { return reader<protocol::ActionRequest>(o); }
  std::unique_ptr<bus::Reader<protocol::WorldStatus>> make_reader(bus::Tag<protocol::WorldStatus>, const bus::EndpointOptions& o) override { return reader<protocol::WorldStatus>(o); }
  std::unique_ptr<bus::Reader<protocol::WorldEvent>> make_reader(bus::Tag<protocol::WorldEvent>, const bus::EndpointOptions& o) override { return reader<protocol::WorldEvent>(o); }
  // clang-format on

 private:
  std::unique_ptr<bus::Participant> inner_;
};

TEST(Monitor, OnlyReadsWithTheContractsQos) {
  ReadOnlySpy spy(72);
  FakeWorld world(72);
  world.publish(final_status("r9", 5));
  StopSource stop;
  std::ostringstream out, err;
  TailOptions options = tail_options(true);
  options.drain = 10ms;
  EXPECT_EQ(run_tail(spy, options, stop, out, err), 0) << err.str();
  EXPECT_EQ(run_status(spy, StatusOptions{}, stop, out, err), 0) << err.str();
  EXPECT_EQ(spy.writers_requested, 0);
  ASSERT_EQ(spy.readers.size(), 3u);
  const std::string status_type = typeid(protocol::WorldStatus).name(),
                    event_type = typeid(protocol::WorldEvent).name();
  // tail: statuses transient-local (a late monitor sees the latest at once), events volatile.
  EXPECT_EQ(spy.readers[0].first, status_type);
  EXPECT_EQ(spy.readers[0].second.durability, bus::Durability::kTransientLocal);
  EXPECT_EQ(spy.readers[1].first, event_type);
  EXPECT_EQ(spy.readers[1].second.durability, bus::Durability::kVolatile);
  EXPECT_EQ(spy.readers[1].second.depth, 256);
  // status: the latest status only.
  EXPECT_EQ(spy.readers[2].first, status_type);
  EXPECT_EQ(spy.readers[2].second.durability, bus::Durability::kTransientLocal);
  EXPECT_EQ(spy.readers[2].second.depth, 1);
  for (const auto& [type, o] : spy.readers) {
    EXPECT_EQ(o.partition, "") << type;
    EXPECT_NE(o.signal, nullptr) << type;
  }
}

}  // namespace
}  // namespace marsala::monitor
