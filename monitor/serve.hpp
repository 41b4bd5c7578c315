#pragma once
// marsala-monitor serve: a live view of a run in the browser (docs/runtime.md#live-view).
//
//   DDS: WorldStatus, WorldEvent --> reader loop (the caller's thread) ----------+
//   DIR/run.log (+ terrain_initial.asc), as it grows, or a paced replay          +--> LiveModel --> published
//     --> follower thread (redraws the terrain picture at most every             |    state (JSON) and terrain
//         terrain_interval_s) -----------------------------------------------------+    picture (PNG)
//   browsers <-- HTTP (own threads): /, /live.js, /live.css, /api/state, /api/terrain.png <-- published
//
// The readers never wait for a browser: the state is rebuilt at most every publish_interval_s and swapped in as one
// immutable string that every request shares; a browser polls and gets the newest one (updates between its polls are
// dropped, never queued), with one request at a time per page. A slow or stalled client holds at most one response
// and is cut off by the socket timeouts.

#include <iosfwd>
#include <memory>
#include <stdexcept>
#include <string>

#include "marsala/bus/bus.hpp"
#include "marsala/monitor/stop_source.hpp"

namespace marsala::monitor {

/// How to serve.
struct ServeOptions {
  std::string bind_address = "127.0.0.1";  ///< numeric IPv4 or IPv6 address to listen on (loopback by default)
  int port = 8080;                         ///< TCP port, 1..65535
  std::string run_dir;             ///< live: the run's --out folder, whose run.log gives the terrain; empty = none
  std::string replay_dir;          ///< replay this run folder instead of following DDS; empty = live
  double replay_steps_per_s = 200.0;  ///< replay pace [steps/s]
  double terrain_interval_s = 0.5;    ///< shortest time between two terrain pictures [s]
  double publish_interval_s = 0.1;    ///< shortest time between two state documents [s]
  int max_picture_px = 1024;          ///< longest side of the terrain picture [px]
};

/// Thrown when the server cannot listen (address in use, not an address of this machine): a usage error (exit 2).
class ListenError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The live view's HTTP server, bound on construction and serving from run() until the stop.
class LiveServer {
 public:
  /// Checks the options and binds the port; throws ListenError naming the address and port and the reason, or
  /// InvalidArgument for a bad option value.
  explicit LiveServer(ServeOptions options);
  ~LiveServer();
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  /// The port it listens on (the one asked for).
  int port() const;

  /// Serves until `stop`: follows `participant`'s WorldStatus and WorldEvent (null in a replay) and the run folder,
  /// prints the address on `out`; returns 0. Problems with the run folder (not there yet, a log that disagrees with
  /// itself) are shown on the page, not fatal.
  int run(bus::Participant* participant, const StopSource& stop, std::ostream& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace marsala::monitor
