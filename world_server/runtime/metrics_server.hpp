#pragma once
// marsala-world --metrics-port: the world's numbers over HTTP in the Prometheus text format (docs/runtime.md#metrics).
//
//   step loop --publish(snapshot)--> [latest snapshot, swapped under a mutex] <--copy of the pointer-- GET /metrics
//                                                                                (HTTP threads render it)
//
// The step loop never waits for a scraper: publishing swaps one shared pointer; a scrape takes a copy of it and
// renders outside the lock.

#include <memory>
#include <string>

#include "marsala/world_server/runtime/metrics_snapshot.hpp"

namespace marsala::world_server {

/// Where to serve.
struct MetricsOptions {
  std::string address = "127.0.0.1";  ///< numeric IPv4 or IPv6 address (loopback by default)
  int port = 0;                        ///< TCP port 1..65535; 0: no metrics server
  double linger_s = 5.0;               ///< after the run's end, keep serving its last values this long [s]
};

/// The HTTP server of the world's metrics: bound on construction, serving from its own threads until destroyed.
class MetricsServer {
 public:
  /// Binds options.address:options.port and starts serving (an empty snapshot until the first publish()); throws
  /// InvalidArgument "--metrics-port P: cannot listen on ADDRESS port P: <why>" when it cannot listen.
  explicit MetricsServer(const MetricsOptions& options);
  ~MetricsServer();
  MetricsServer(const MetricsServer&) = delete;
  MetricsServer& operator=(const MetricsServer&) = delete;

  /// Makes `snapshot` the one every later scrape renders; never waits for a scrape in progress.
  void publish(std::shared_ptr<const MetricsSnapshot> snapshot);
  /// The latest snapshot published (an empty one before the first).
  std::shared_ptr<const MetricsSnapshot> latest() const;
  /// Scrapes answered so far [count].
  std::uint64_t scrapes() const;
  /// The port it listens on.
  int port() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace marsala::world_server
