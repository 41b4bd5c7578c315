#include "marsala/monitor/signal_watcher.hpp"

#include <pthread.h>

#include <csignal>
#include <cstring>

#include "marsala/core/error.hpp"

namespace marsala::monitor {
namespace {

sigset_t stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}

}  // namespace

SignalWatcher::SignalWatcher(StopSource& stop) {
  const sigset_t set = stop_signals();
  if (const int rc = pthread_sigmask(SIG_BLOCK, &set, nullptr); rc != 0)
    throw Error(std::string("cannot block SIGINT/SIGTERM: ") + std::strerror(rc));
  thread_ = std::thread([this, &stop] {
    const sigset_t waited = stop_signals();
    for (;;) {
      int signal_number = 0;
      if (sigwait(&waited, &signal_number) != 0) continue;
      if (closing_.load()) return;
      stop.request_stop();
    }
  });
}

SignalWatcher::~SignalWatcher() {
  // Wake the watcher with a signal of its own set; `closing_` tells it this one is not a stop request.
  closing_.store(true);
  pthread_kill(thread_.native_handle(), SIGTERM);
  thread_.join();
}

}  // namespace marsala::monitor
