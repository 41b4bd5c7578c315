// The marsala-monitor command line: in-process (exit codes, options, output), and the real binary for
// what only a process can show (Ctrl-C / SIGTERM end it cleanly).
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <sstream>
#include <string>
#include <vector>

#include "marsala/monitor/format.hpp"
#include "marsala/monitor/monitor_cli.hpp"
#include "unit/monitor/fake_world.hpp"

extern char** environ;

namespace marsala::monitor {
namespace {

using namespace std::chrono_literals;
using test_support::FakeWorld;

struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

Result run_cli(std::vector<std::string> args, const StopSource& stop = StopSource{}) {
  args.insert(args.begin(), "marsala-monitor");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  Result r;
  r.exit_code = run_monitor_cli(static_cast<int>(argv.size()), argv.data(), out, err, stop);
  r.out = out.str();
  r.err = err.str();
  return r;
}

protocol::WorldStatus one_agent_status(std::uint64_t step, bool running) {
  protocol::WorldStatus s;
  s.run_id = "cli";
  s.scenario = "flat";
  s.step = step;
  s.running = running;
  protocol::AgentStatus a;
  a.agent_id = 1;
  a.name = "solo";
  a.state = "build";
  s.agents.push_back(a);
  return s;
}

TEST(MonitorCli, HelpForTheToolAndEachSubcommand) {
  const Result top = run_cli({"--help"});
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_NE(top.out.find("tail"), std::string::npos);
  EXPECT_NE(top.out.find("status"), std::string::npos);
  const Result tail = run_cli({"tail", "--help"});
  EXPECT_EQ(tail.exit_code, 0);
  for (const char* option : {"--dds", "--domain", "--run-id", "--events", "--timeout", "--width"})
    EXPECT_NE(tail.out.find(option), std::string::npos) << option;
  const Result status = run_cli({"status", "--help"});
  EXPECT_EQ(status.exit_code, 0);
  for (const char* option : {"--dds", "--domain", "--timeout"})
    EXPECT_NE(status.out.find(option), std::string::npos) << option;
  EXPECT_EQ(status.out.find("--events"), std::string::npos);
}

TEST(MonitorCli, UsageErrorsExitTwo) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {},
           {"replay"},
           {"tail", "--dds", "opensplice"},
           {"tail", "--domain", "233"},
           {"tail", "--timeout", "0"},
           {"tail", "--width", "-1"},
           {"status", "--timeout", "x"},
           {"status", "--events"},
           {"status", "extra"},
       }) {
    const Result r = run_cli(args);
    std::string joined;
    for (const std::string& a : args) joined += a + " ";
    EXPECT_EQ(r.exit_code, 2) << joined;
    EXPECT_EQ(r.err.rfind("marsala-monitor: ", 0), 0u) << joined << ": " << r.err;
    EXPECT_EQ(r.out, "") << joined;
  }
}

TEST(MonitorCli, StatusPrintsTheTable) {
  FakeWorld world(80);
  world.publish(one_agent_status(12, true));
  const Result r = run_cli({"status", "--dds", "inprocess", "--domain", "80"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> expected = {
      "run cli  scenario flat  step 12  wall 0.0 s  running  progress 0.0%  deposited 0.0000 m3",
      " id name         state           x[m]     y[m]    z[m] mat[m3] dep[m3]   acc  rej miss alive goal",
      "  1 solo         build           0.00     0.00   0.000  0.0000  0.0000     0    0    0 yes   no",
      "    total        1 agent                                0.0000  0.0000     0    0    0 1     0",
  };
  std::string text;
  for (const std::string& line : expected) text += line + "\n";
  EXPECT_EQ(r.out, text);
}

TEST(MonitorCli, StatusWithoutAWorldExitsOne) {
  const Result r = run_cli({"status", "--dds", "inprocess", "--domain", "81", "--timeout", "0.1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "marsala-monitor: no world server on domain 81 (inprocess): no world status within 0.1 s\n");
}

TEST(MonitorCli, JsonLogFormatMakesTheErrorOneRecordWhereverTheOptionStands) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--log-format", "json", "status", "--dds", "inprocess", "--domain", "81", "--timeout",
                                 "0.1"},
        std::vector<std::string>{"status", "--dds", "inprocess", "--domain", "81", "--timeout", "0.1", "--log-format",
                                 "json"}}) {
    const Result r = run_cli(args);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err.find("marsala-monitor: "), std::string::npos) << r.err;  // the prefix gives way to the record's
    EXPECT_EQ(r.err.front(), '{') << r.err;
    EXPECT_EQ(r.err.substr(r.err.size() - 2), "}\n") << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("\"level\":\"error\",\"process\":\"monitor\",\"agent_id\":null,"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\"msg\":\"no world server on domain 81 (inprocess): no world status within 0.1 s\"}"),
              std::string::npos)
        << r.err;
  }
}

TEST(MonitorCli, TailFollowsARunToItsEnd) {
  FakeWorld world(82);
  auto tail = std::async(std::launch::async, [] {
    return run_cli({"tail", "--dds", "inprocess", "--domain", "82", "--events", "--run-id", "cli", "--timeout", "10",
                    "--width", "60"});
  });
  ASSERT_TRUE(world.wait_for_monitor(1, 1));
  protocol::WorldEvent over;
  over.step = 4;
  over.kind = protocol::EventKind::kRunOver;
  over.detail = "max_steps reached";
  world.publish(one_agent_status(3, true));
  world.publish(over);
  world.publish(one_agent_status(4, false));
  ASSERT_EQ(tail.wait_for(10s), std::future_status::ready);
  const Result r = tail.get();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out,
            "  step  live mat[m3]  dep[m3] prog | 1\n"
            "     3   1/1    0.00    0.000   0% | build\n"
            "     4 > world    run_over  max_steps reached\n"
            "     4   1/1    0.00    0.000   0% | build\n"
            "run cli stopped at step 4 (0.0 s) | live 1/1, at goal 0 | dep 0.000 m3 | acc 0 rej 0 miss 0\n");
  EXPECT_EQ(r.err, "marsala-monitor: tailing domain 82 (inprocess), run cli; Ctrl-C stops\n");
}

TEST(MonitorCli, TailWithoutStatusTimesOut) {
  const Result r = run_cli({"tail", "--dds", "inprocess", "--domain", "83", "--timeout", "0.1"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("marsala-monitor: no world status on domain 83 (inprocess) for 0.1 s"), std::string::npos)
      << r.err;
}

TEST(MonitorCli, StatusStoppedBeforeAWorldExitsOne) {
  // Ctrl-C while status still waits for a world: nothing to show, so not a success.
  StopSource stop;
  stop.request_stop();
  const Result r = run_cli({"status", "--dds", "inprocess"}, stop);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "marsala-monitor: stopped before a world status arrived\n");
}

/// The real binary as a child process, its stdout and stderr on pipes.
class Child {
 public:
  explicit Child(const std::vector<std::string>& args) {
    int out_pipe[2], err_pipe[2];
    EXPECT_EQ(pipe(out_pipe), 0);
    EXPECT_EQ(pipe(err_pipe), 0);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out_pipe[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, err_pipe[1], STDERR_FILENO);
    posix_spawn_file_actions_addclose(&actions, out_pipe[0]);
    posix_spawn_file_actions_addclose(&actions, err_pipe[0]);
    std::vector<std::string> all = {MARSALA_MONITOR_BIN};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    EXPECT_EQ(posix_spawn(&pid_, MARSALA_MONITOR_BIN, &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    close(out_pipe[1]);
    close(err_pipe[1]);
    out_fd_ = out_pipe[0];
    err_fd_ = err_pipe[0];
  }
  ~Child() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    close(out_fd_);
    close(err_fd_);
  }

  /// Reads stderr until it contains `marker` (false after 5 s without it).
  bool wait_for_stderr(const std::string& marker) {
    while (err_.find(marker) == std::string::npos)
      if (!read_some(err_fd_, err_)) return false;
    return true;
  }
  void signal(int number) { kill(pid_, number); }
  /// Reads both pipes to their end, then reaps the child: its exit code, or -1 if a signal killed it.
  int wait_exit() {
    while (read_some(out_fd_, out_)) {
    }
    while (read_some(err_fd_, err_)) {
    }
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  const std::string& out() const { return out_; }
  const std::string& err() const { return err_; }

 private:
  /// Appends what `fd` has within 5 s; false at its end or on timeout.
  static bool read_some(int fd, std::string& into) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, 5000) <= 0) return false;
    char buffer[4096];
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n <= 0) return false;
    into.append(buffer, static_cast<std::size_t>(n));
    return true;
  }

  pid_t pid_ = -1;
  int out_fd_ = -1;
  int err_fd_ = -1;
  std::string out_;
  std::string err_;
};

TEST(MonitorBinary, CtrlCAndSigtermEndTailCleanly) {
  for (int number : {SIGINT, SIGTERM}) {
    Child child({"tail", "--dds", "inprocess", "--domain", "84"});
    ASSERT_TRUE(child.wait_for_stderr("Ctrl-C stops\n")) << child.err();
    child.signal(number);
    EXPECT_EQ(child.wait_exit(), 0) << "signal " << number << ": " << child.err();
    EXPECT_EQ(child.out(), "tail stopped before any world status\n");
  }
}

TEST(MonitorBinary, ExitCodes) {
  Child usage({"tail", "--domain", "999"});
  EXPECT_EQ(usage.wait_exit(), 2);
  Child no_world({"status", "--dds", "inprocess", "--domain", "85", "--timeout", "0.05"});
  EXPECT_EQ(no_world.wait_exit(), 1);
  EXPECT_NE(no_world.err().find("no world server on domain 85"), std::string::npos) << no_world.err();
  Child help({"--help"});
  EXPECT_EQ(help.wait_exit(), 0);
  EXPECT_NE(help.out().find("Subcommands:"), std::string::npos);
}

}  // namespace
}  // namespace marsala::monitor
