// marsala-bus-probe: one end of a multi-process bus test. Prints one line per event on stdout (flushed), so the
// test that starts it can follow it; exit codes say how it ended.
//
//   write  --dds V --domain D --partition P [--count N] [--tiles T] [--readers R]
//          waits until R readers matched, writes frames 0..N-1 (contents: probe_frames.hpp), then holds its
//          writer until SIGTERM/SIGINT (or is SIGKILLed). Lines: "matched", "written N".
//   read   --dds V --domain D --partition P [--count N] [--tiles T] [--timeout-s S]
//          checks every frame bit for bit; exits 0 after N good frames, or on SIGTERM with none expected and
//          none received. Lines: "ready", "received N". Exit 1: a wrong or unexpected frame; 2: timeout.
//   alive  --dds V --domain D --partition P [--timeout-s S]
//          follows alive_writers(); exits 0 once it dropped back to 0. Lines: "alive N".
//   open-request --dds V --domain D --partition P
//          opens an ActionRequest writer on P; prints "opened" and holds it until SIGTERM (exit 3: refused).
//   Every mode takes --role server|client (default server): the participant's place in the discovery star (bus.hpp),
//   and --security DIR --identity NAME: DDS Security with DIR/NAME.pem (deploy/security/make-identities.sh).
//   idle   --dds V --domain D
//          an idle agent's endpoints (hello writer, admission reader, frame reader, request writer); prints
//          "created <ms>" and, after 2 s, "rss_kb <VmRSS>"; holds until SIGTERM.

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <thread>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"
#include "probe_frames.hpp"

namespace {

using namespace std::chrono_literals;
using namespace marsala::bus;
using namespace marsala::protocol;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

void say(const std::string& line) {
  std::cout << line << std::endl;  // endl flushes: the parent reads line by line
}

struct Args {
  std::string mode;
  std::map<std::string, std::string> flags;
  std::string get(const std::string& name, const std::string& fallback) const {
    auto it = flags.find(name);
    return it == flags.end() ? fallback : it->second;
  }
  int number(const std::string& name, int fallback) const { return std::stoi(get(name, std::to_string(fallback))); }
};

Args parse(int argc, char** argv) {
  if (argc < 2) throw marsala::InvalidArgument("usage: marsala-bus-probe write|read|alive|idle --dds V --domain D ...");
  Args args{argv[1], {}};
  for (int i = 2; i + 1 < argc; i += 2) {
    if (std::strncmp(argv[i], "--", 2) != 0) throw marsala::InvalidArgument(std::string("unexpected ") + argv[i]);
    args.flags[argv[i] + 2] = argv[i + 1];
  }
  return args;
}

long rss_kb() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      long kb = 0;
      status >> kb;
      return kb;
    }
    status.ignore(4096, '\n');
  }
  return -1;
}

/// Waits until `done()` or a stop signal or `timeout`; true when done.
template <typename Done>
bool wait(Signal& signal, Done done, Clock::duration timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!done()) {
    if (g_stop || Clock::now() >= deadline) return false;
    signal.wait_for(50ms);
  }
  return true;
}

int run_write(Participant& participant, const Args& args) {
  const int count = args.number("count", 10);
  const int tiles = args.number("tiles", 40);
  auto writer = participant.create_writer<SensorFrame>({args.get("partition", ""), nullptr});
  const auto deadline = Clock::now() + 30s;
  while (writer->matched_readers() < args.number("readers", 1)) {
    if (g_stop || Clock::now() >= deadline) return 2;
    std::this_thread::sleep_for(5ms);  // a writer has no signal to wait on
  }
  say("matched");
  for (int step = 0; step < count; ++step)
    writer->write(marsala::probe::frame(static_cast<std::uint64_t>(step), tiles));
  say("written " + std::to_string(count));
  Signal idle;
  while (!g_stop) idle.wait_for(50ms);
  return 0;
}

// Opens an ActionRequest writer on --partition (what an agent opens on its session's partition) and holds it until
// SIGTERM: prints "opened"; exit 3 when the participant may not (DDS Security refuses it).
int run_open_request(Participant& participant, const Args& args) {
  auto writer = participant.create_writer<ActionRequest>({args.get("partition", ""), nullptr});
  say("opened");
  Signal idle;
  while (!g_stop) idle.wait_for(50ms);
  return 0;
}

int run_read(Participant& participant, const Args& args) {
  const int count = args.number("count", 10);
  const int tiles = args.number("tiles", 40);
  auto signal = std::make_shared<Signal>();
  auto reader = participant.create_reader<SensorFrame>({args.get("partition", ""), signal});
  say("ready");
  int received = 0;
  bool wrong = false;
  auto check = [&] {
    for (const SensorFrame& f : reader->take()) {
      if (received >= count || f.step != static_cast<std::uint64_t>(received) ||
          !marsala::probe::same(f, marsala::probe::frame(f.step, tiles))) {
        wrong = true;
        std::cerr << "probe: unexpected or wrong frame, step " << f.step << " (frame " << received
                  << " expected): " << marsala::probe::first_difference(f, marsala::probe::frame(f.step, tiles))
                  << std::endl;
      }
      ++received;
    }
    return wrong || (count > 0 && received >= count);
  };
  const bool done = wait(*signal, check, std::chrono::seconds(args.number("timeout-s", 30)));
  check();
  say("received " + std::to_string(received));
  if (wrong) return 1;
  if (count == 0) return g_stop && received == 0 ? 0 : 2;
  return done && received == count ? 0 : 2;
}

int run_alive(Participant& participant, const Args& args) {
  auto signal = std::make_shared<Signal>();
  auto reader = participant.create_reader<SensorFrame>({args.get("partition", ""), signal});
  int last = reader->alive_writers();
  bool seen = false;
  say("alive " + std::to_string(last));
  const auto deadline = Clock::now() + std::chrono::seconds(args.number("timeout-s", 30));
  while (!g_stop && Clock::now() < deadline) {
    signal->wait_for(20ms);
    const int now = reader->alive_writers();
    if (now != last) say("alive " + std::to_string(now));
    last = now;
    seen = seen || now > 0;
    if (seen && now == 0) return 0;
  }
  return 2;
}

int run_idle(Participant& participant, const Args&, Clock::time_point start) {
  auto signal = std::make_shared<Signal>();
  auto hello = participant.create_writer<AgentHello>();
  auto admission = participant.create_reader<Admission>({"", signal});
  auto frames = participant.create_reader<SensorFrame>({partition_for("rss", 1, 1), signal});
  auto requests = participant.create_writer<ActionRequest>({partition_for("rss", 1, 1), nullptr});
  const auto created = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start).count();
  say("created " + std::to_string(created));
  const auto settle = Clock::now() + 2s;
  while (!g_stop && Clock::now() < settle) signal->wait_for(50ms);
  say("rss_kb " + std::to_string(rss_kb()));
  while (!g_stop) signal->wait_for(50ms);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  try {
    const Args args = parse(argc, argv);
    const auto start = Clock::now();
    const std::string role = args.get("role", "server");
    if (role != "server" && role != "client")
      throw marsala::InvalidArgument("unknown --role '" + role + "'; valid: server, client");
    auto participant = make_participant({vendor_from_string(args.get("dds", "cyclone")),
                                         args.number("domain", 0),
                                         {},
                                         role == "client" ? Role::kClient : Role::kWorld,
                                         {args.get("security", ""), args.get("identity", "")}});
    if (args.mode == "write") return run_write(*participant, args);
    if (args.mode == "read") return run_read(*participant, args);
    if (args.mode == "alive") return run_alive(*participant, args);
    if (args.mode == "idle") return run_idle(*participant, args, start);
    if (args.mode == "open-request") return run_open_request(*participant, args);
    throw marsala::InvalidArgument("unknown mode '" + args.mode + "'; valid: write, read, alive, idle, open-request");
  } catch (const std::exception& e) {
    std::cerr << "marsala-bus-probe: " << e.what() << std::endl;
    return 3;
  }
}
