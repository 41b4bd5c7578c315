// The bus across processes: marsala-bus-probe processes of either vendor, per vendor pair. Frames travel bit for
// bit and only within their partition; a SIGKILLed writer process is seen as not alive within a few seconds (and an
// idle live one never is); two clients of the discovery star never find each other; an idle agent's participant
// stays small; a foreign type under a message's name costs a reader bounded log and no genuine frame. Run under
// run_isolated.sh (private network namespace) with the loopback configs in the environment (CMakeLists.txt). Domains
// 160..163, 180..193.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "marsala/bus/bus.hpp"

namespace marsala::bus {
using namespace marsala::protocol;  // the messages under test
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

/// A child process whose stdout is read line by line.
class Child {
 public:
  /// Runs `args`; its stderr goes to the file `stderr_path` when one is given.
  explicit Child(const std::vector<std::string>& args, const std::string& stderr_path = "") {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      if (!stderr_path.empty()) {
        const int err = open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (err >= 0) dup2(err, STDERR_FILENO);
      }
      close(fds[0]);
      close(fds[1]);
      std::vector<char*> argv;
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(fds[1]);
    fd_ = fds[0];
  }
  ~Child() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (fd_ >= 0) close(fd_);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// The next line of output within `timeout`; nothing on timeout or end of output.
  std::optional<std::string> next_line(Clock::duration timeout) {
    const auto deadline = Clock::now() + timeout;
    for (;;) {
      const auto newline = buffer_.find('\n');
      if (newline != std::string::npos) {
        std::string line = buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        return line;
      }
      if (eof_) return std::nullopt;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0) return std::nullopt;
      pollfd p{fd_, POLLIN, 0};
      if (poll(&p, 1, static_cast<int>(left)) <= 0) continue;
      char chunk[4096];
      const ssize_t n = read(fd_, chunk, sizeof chunk);
      if (n <= 0)
        eof_ = true;
      else
        buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }
  /// Reads output until a line equal to `expected` arrives; false on timeout or end of output.
  bool expect_line(const std::string& expected, Clock::duration timeout) {
    const auto deadline = Clock::now() + timeout;
    while (auto line = next_line(deadline - Clock::now())) {
      last_ = *line;
      if (*line == expected) return true;
    }
    return false;
  }
  /// Drains the output and returns the exit code (-1 if not exited within `timeout`, then killed; 128+n on signal n).
  int wait_exit(Clock::duration timeout) {
    const auto deadline = Clock::now() + timeout;
    while (auto line = next_line(deadline - Clock::now())) last_ = *line;
    int status = 0;
    if (!eof_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &status, 0);
      pid_ = -1;
      return -1;
    }
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  void send(int sig) { kill(pid_, sig); }
  const std::string& last_line() const { return last_; }

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
  std::string buffer_;
  std::string last_;
  bool eof_ = false;
};

struct Pair {
  Vendor writer;
  Vendor reader;
  int index;
};

std::string pair_name(const ::testing::TestParamInfo<Pair>& info) {
  return to_string(info.param.writer) + "_to_" + to_string(info.param.reader);
}

std::vector<std::string> probe(const std::string& mode, Vendor vendor, int domain, std::vector<std::string> more) {
  std::vector<std::string> args{MARSALA_BUS_PROBE, mode,       "--dds",
                                to_string(vendor), "--domain", std::to_string(domain)};
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

class BusAcrossProcesses : public ::testing::TestWithParam<Pair> {};

/// Starts `reader` (expecting `count` frames) and `silent` (expecting none; any frame makes it exit 1 at once), then a
/// writer with `writer_args` that writes `count` frames once one reader matched; checks that `reader` got them all and
/// that `silent` got nothing within `leak_wait` after them.
void expect_delivered_only_to(Child& reader, Child& silent, std::vector<std::string> writer_args, int count,
                              Clock::duration leak_wait) {
  ASSERT_TRUE(reader.expect_line("ready", 10s));
  ASSERT_TRUE(silent.expect_line("ready", 10s));
  Child writer(writer_args);
  ASSERT_TRUE(writer.expect_line("matched", 20s)) << writer.last_line();
  ASSERT_TRUE(writer.expect_line("written " + std::to_string(count), 10s)) << writer.last_line();
  EXPECT_EQ(reader.wait_exit(30s), 0) << "reader: " << reader.last_line();
  EXPECT_EQ(reader.last_line(), "received " + std::to_string(count));
  std::optional<std::string> leak = silent.next_line(leak_wait);
  EXPECT_FALSE(leak.has_value()) << "a frame reached the reader that must get none: " << *leak;
  silent.send(SIGTERM);
  EXPECT_EQ(silent.wait_exit(10s), 0) << "silent reader: " << silent.last_line();
  EXPECT_EQ(silent.last_line(), "received 0");
  writer.send(SIGTERM);
  EXPECT_EQ(writer.wait_exit(10s), 0);
}

TEST_P(BusAcrossProcesses, FramesArriveBitForBitAndOnlyInTheirPartition) {
  const int domain = 180 + 2 * GetParam().index;
  Child reader(probe("read", GetParam().reader, domain,
                     {"--partition", "run-x/agent-1", "--count", "20", "--tiles", "40", "--timeout-s", "30"}));
  Child other(probe("read", GetParam().reader, domain,
                    {"--partition", "run-x/agent-2", "--count", "0", "--tiles", "40", "--timeout-s", "60"}));
  // The reader of the other partition runs all along.
  expect_delivered_only_to(
      reader, other,
      probe("write", GetParam().writer, domain,
            {"--partition", "run-x/agent-1", "--count", "20", "--tiles", "40", "--readers", "1"}),
      20, 300ms);
}

TEST_P(BusAcrossProcesses, AKilledWriterProcessIsSoonNotAlive) {
  const int domain = 181 + 2 * GetParam().index;
  Child watcher(probe("alive", GetParam().reader, domain, {"--partition", "run-k/agent-1", "--timeout-s", "40"}));
  ASSERT_TRUE(watcher.expect_line("alive 0", 10s));
  Child writer(probe("write", GetParam().writer, domain, {"--partition", "run-k/agent-1", "--count", "0"}));
  ASSERT_TRUE(writer.expect_line("matched", 20s));
  ASSERT_TRUE(watcher.expect_line("alive 1", 10s)) << watcher.last_line();
  // An idle writer is asserted alive by its participant: no change for several leases.
  std::optional<std::string> change = watcher.next_line(3s);
  EXPECT_FALSE(change.has_value()) << "an idle live writer went: " << *change;
  const auto killed = Clock::now();
  writer.send(SIGKILL);
  ASSERT_TRUE(watcher.expect_line("alive 0", 10s)) << watcher.last_line();
  const auto detected_ms = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - killed).count();
  std::printf("killed %s writer seen not alive by a %s reader after %lld ms\n", to_string(GetParam().writer).c_str(),
              to_string(GetParam().reader).c_str(), static_cast<long long>(detected_ms));
  RecordProperty("detected_ms", static_cast<int>(detected_ms));
  EXPECT_LT(detected_ms, 4000);
  EXPECT_EQ(watcher.wait_exit(10s), 0);
}

// The discovery star (bus.hpp Role): a client's frames reach a server's reader, never another client's reader in the
// same partition, which would receive them (transient-local, so even a late match would deliver them) if the two
// clients ever discovered each other.
TEST_P(BusAcrossProcesses, ClientsFindTheServerButNotEachOther) {
  const int domain = 160 + GetParam().index;
  Child server(probe("read", GetParam().reader, domain,
                     {"--partition", "run-s/agent-1", "--count", "10", "--timeout-s", "30"}));
  Child client(probe("read", GetParam().reader, domain,
                     {"--role", "client", "--partition", "run-s/agent-1", "--count", "0", "--timeout-s", "60"}));
  // Clients announce themselves every second at most: three seconds are several chances to meet.
  expect_delivered_only_to(
      server, client,
      probe("write", GetParam().writer, domain,
            {"--role", "client", "--partition", "run-s/agent-1", "--count", "10", "--readers", "1"}),
      10, 3s);
}

// A foreign type under SensorFrame's name (another layout) floods the reader's partition while 20 genuine frames come
// (docs/runtime.md#foreign-types): the reader gets all 20, bit for bit and nothing else, and its log (stderr) stays
// within a few lines: Cyclone's line per undecodable sample is written at the 1st, 10th, 100th ... only.
TEST_P(BusAcrossProcesses, AForeignTypeCostsBoundedLogAndNoGenuineFrame) {
  const int domain = 190 + GetParam().index;
  const std::string log = ::testing::TempDir() + "/foreign_reader_" + std::to_string(getpid()) + ".log";
  Child reader(probe("read", GetParam().reader, domain,
                     {"--partition", "run-f/agent-1", "--count", "20", "--tiles", "40", "--timeout-s", "40"}),
               log);
  ASSERT_TRUE(reader.expect_line("ready", 10s));
  Child foreign({MARSALA_FOREIGN_TYPE, std::to_string(domain), "SensorFrame", "run-f/agent-1", "3"});
  ASSERT_TRUE(foreign.expect_line("matched", 25s)) << foreign.last_line();
  Child writer(probe("write", GetParam().writer, domain,
                     {"--partition", "run-f/agent-1", "--count", "20", "--tiles", "40", "--readers", "1"}));
  ASSERT_TRUE(writer.expect_line("matched", 20s)) << writer.last_line();
  // Every genuine frame, bit for bit and in order, on both vendors (docs/runtime.md#foreign-types).
  EXPECT_EQ(reader.wait_exit(40s), 0) << "reader: " << reader.last_line();
  EXPECT_EQ(reader.last_line(), "received 20");
  EXPECT_EQ(foreign.wait_exit(20s), 0) << foreign.last_line();
  std::printf("%s; %s reader: ", foreign.last_line().c_str(), to_string(GetParam().reader).c_str());
  writer.send(SIGTERM);
  EXPECT_EQ(writer.wait_exit(10s), 0);
  std::ifstream in(log);
  int lines = 0;
  for (std::string line; std::getline(in, line);) lines += line.empty() ? 0 : 1;
  std::printf("%d log lines\n", lines);
  EXPECT_LE(lines, 12) << "the reader's log grew under the foreign flood (" << log << ")";
  std::remove(log.c_str());
}

INSTANTIATE_TEST_SUITE_P(Pairs, BusAcrossProcesses,
                         ::testing::Values(Pair{Vendor::kCyclone, Vendor::kCyclone, 0},
                                           Pair{Vendor::kFastDds, Vendor::kFastDds, 1},
                                           Pair{Vendor::kCyclone, Vendor::kFastDds, 2},
                                           Pair{Vendor::kFastDds, Vendor::kCyclone, 3}),
                         pair_name);

// An idle agent: participant, hello writer, admission reader, frame reader, request writer.
TEST(BusFootprint, AnIdleAgentParticipantStaysUnder30MB) {
  for (Vendor v : {Vendor::kCyclone, Vendor::kFastDds}) {
    Child agent(probe("idle", v, 188, {}));
    const auto created = agent.next_line(15s);
    ASSERT_TRUE(created && created->rfind("created ", 0) == 0) << to_string(v);
    const auto rss = agent.next_line(15s);
    ASSERT_TRUE(rss && rss->rfind("rss_kb ", 0) == 0) << to_string(v);
    const long kb = std::stol(rss->substr(7));
    std::printf("%s: participant + 4 endpoints created in %s ms, RSS %ld kB\n", to_string(v).c_str(),
                created->substr(8).c_str(), kb);
    EXPECT_LT(kb, 30 * 1024) << to_string(v);
    EXPECT_LT(std::stol(created->substr(8)), 2000) << to_string(v) << ": creation should be quick";
    agent.send(SIGTERM);
    EXPECT_EQ(agent.wait_exit(10s), 0);
  }
}

}  // namespace
}  // namespace marsala::bus
