// marsala-world: the authoritative world server of a MARSala run.
#include <atomic>
#include <csignal>
#include <iostream>

#include "marsala/world_server/runtime/world_cli.hpp"

namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  return marsala::world_server::run_world_cli(argc, argv, g_stop, std::cout, std::cerr);
}
