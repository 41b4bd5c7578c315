// Round trip of a small sample (an ActionRequest without depositions) through the bus between two processes over
// loopback UDP: this process pings on partition "ping", a forked-and-exec'd child of this binary ("--pong") echoes
// on "pong". Per vendor pair; the baseline the lockstep benchmark is compared to. Each iteration is one round trip
// (write, listener thread, queue, Signal wake-up, take, on both sides); counters p50_us / p99_us are percentiles of
// the individual round trips. Loopback DDS configs (deploy/dds) are used unless the environment names others.
//
//   build/bench/bus_pingpong_bench [--benchmark_filter=cyclone]

#include <benchmark/benchmark.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "marsala/bus/bus.hpp"

namespace {

using namespace std::chrono_literals;
using namespace marsala::bus;
using Clock = std::chrono::steady_clock;

constexpr const char* kStop = "stop";
std::string g_self;

/// The child: echoes every ping back until told to stop (or its parent dies).
int run_pong(Vendor vendor, int domain) {
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  auto participant = make_participant({vendor, domain});
  auto signal = std::make_shared<Signal>();
  auto pings = participant->create_reader<ActionRequest>({"ping", signal});
  auto pongs = participant->create_writer<ActionRequest>({"pong", nullptr});
  for (;;) {
    signal->wait_for(1s);
    for (const ActionRequest& r : pings->take()) {
      if (r.state == kStop) return 0;
      pongs->write(r);
    }
  }
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

void BM_BusPingPong(benchmark::State& state, Vendor ping, Vendor pong, int domain) {
  const pid_t child = fork();
  if (child == 0) {
    execl(g_self.c_str(), g_self.c_str(), "--pong", to_string(pong).c_str(), std::to_string(domain).c_str(), nullptr);
    _exit(127);
  }
  {
    auto participant = make_participant({ping, domain});
    auto signal = std::make_shared<Signal>();
    auto pongs = participant->create_reader<ActionRequest>({"pong", signal});
    auto pings = participant->create_writer<ActionRequest>({"ping", nullptr});
    const auto deadline = Clock::now() + 20s;
    while (pings->matched_readers() < 1 || pongs->alive_writers() < 1) {
      if (Clock::now() > deadline) {
        state.SkipWithError("the pong process was not discovered within 20 s");
        break;
      }
      signal->wait_for(10ms);
    }
    ActionRequest request;
    request.agent_id = 1;
    request.session = 42;
    request.move = true;
    request.state = "climb";
    auto round_trip = [&](std::uint64_t step) {
      request.step = step;
      pings->write(request);
      for (;;) {
        for (const ActionRequest& r : pongs->take())
          if (r.step == step) return true;
        if (!signal->wait_for(2s)) return false;
      }
    };
    std::uint64_t step = 0;
    for (int i = 0; i < 100 && !state.error_occurred(); ++i) round_trip(++step);  // warm up
    std::vector<double> rtt_us;
    for (auto _ : state) {
      const auto t0 = Clock::now();
      if (!round_trip(++step)) {
        state.SkipWithError("a round trip took longer than 2 s");
        break;
      }
      rtt_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    }
    state.counters["p50_us"] = percentile(rtt_us, 0.50);
    state.counters["p99_us"] = percentile(rtt_us, 0.99);
    request.state = kStop;
    pings->write(request);
    std::this_thread::sleep_for(100ms);  // let the stop reach the child before this participant goes
  }
  int status = 0;
  const auto deadline = Clock::now() + 5s;
  while (waitpid(child, &status, WNOHANG) == 0) {
    if (Clock::now() > deadline) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      break;
    }
    std::this_thread::sleep_for(10ms);
  }
}

BENCHMARK_CAPTURE(BM_BusPingPong, cyclone, Vendor::kCyclone, Vendor::kCyclone, 190)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_BusPingPong, fastdds, Vendor::kFastDds, Vendor::kFastDds, 191)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_BusPingPong, cyclone_to_fastdds, Vendor::kCyclone, Vendor::kFastDds, 192)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_BusPingPong, fastdds_to_cyclone, Vendor::kFastDds, Vendor::kCyclone, 193)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  // Both processes stay on loopback: the child inherits these.
  setenv("CYCLONEDDS_URI", "file://" MARSALA_SOURCE_DIR "/deploy/dds/cyclone-lo.xml", 0);
  setenv("FASTRTPS_DEFAULT_PROFILES_FILE", MARSALA_SOURCE_DIR "/deploy/dds/fastdds-lo.xml", 0);
  char self[4096] = {};
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  g_self = n > 0 ? std::string(self, static_cast<std::size_t>(n)) : std::string(argv[0]);
  try {
    if (argc == 4 && std::strcmp(argv[1], "--pong") == 0)
      return run_pong(vendor_from_string(argv[2]), std::atoi(argv[3]));
  } catch (const std::exception& e) {
    std::cerr << "bus_pingpong_bench --pong: " << e.what() << std::endl;
    return 1;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
