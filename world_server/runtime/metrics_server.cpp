#include "marsala/world_server/runtime/metrics_server.hpp"

#include <fmt/format.h>
#include <httplib.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <thread>
#include <utility>

#include "marsala/cli/listen_problem.hpp"
#include "marsala/core/cpu_time.hpp"
#include "marsala/core/error.hpp"
#include "marsala/world_server/runtime/metrics_exposition.hpp"

namespace marsala::world_server {
namespace {

/// HTTP worker threads: a scrape renders a few kB from a snapshot; two serve Prometheus and a person's curl at once.
constexpr std::size_t kHttpThreads = 2;
/// A client that does not take its response within this long is cut off [s].
constexpr time_t kSocketTimeoutS = 5;

/// This process's CPU time and resident memory now, and `started` [s since the epoch].
ProcessMetrics process_now(double started) {
  ProcessMetrics p;
  p.cpu_seconds = process_cpu_ms() / 1e3;
  p.start_time_seconds = started;
  long pages = 0, resident = 0;
  if (std::FILE* statm = std::fopen("/proc/self/statm", "r")) {  // "size resident ..." in pages (proc(5))
    if (std::fscanf(statm, "%ld %ld", &pages, &resident) == 2)
      p.resident_memory_bytes = static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE));
    std::fclose(statm);
  }
  return p;
}

}  // namespace

struct MetricsServer::Impl {
  MetricsOptions options;
  httplib::Server http;
  std::thread thread;
  mutable std::mutex mutex;
  std::shared_ptr<const MetricsSnapshot> latest = std::make_shared<const MetricsSnapshot>();
  std::atomic<std::uint64_t> scrapes{0};
  /// When the server started, since the epoch [s]: the process's start to within milliseconds (it starts before the
  /// run's folder is touched).
  double started_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();

  std::shared_ptr<const MetricsSnapshot> current() const {
    std::lock_guard<std::mutex> lock(mutex);
    return latest;
  }
};

MetricsServer::MetricsServer(const MetricsOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& impl = *impl_;
  impl.options = options;
  if (options.port < 1 || options.port > 65535)
    throw InvalidArgument(fmt::format("--metrics-port {}: must be a TCP port, 1..65535", options.port));
  impl.http.new_task_queue = [] { return new httplib::ThreadPool(kHttpThreads); };
  impl.http.set_read_timeout(kSocketTimeoutS, 0);
  impl.http.set_write_timeout(kSocketTimeoutS, 0);
  impl.http.set_payload_max_length(1 << 12);
  impl.http.Get("/metrics", [&impl](const httplib::Request&, httplib::Response& res) {
    const std::shared_ptr<const MetricsSnapshot> snapshot = impl.current();
    res.set_content(render_metrics(*snapshot) + render_process_metrics(process_now(impl.started_s)),
                    kMetricsContentType);
    ++impl.scrapes;
  });
  impl.http.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content("marsala-world: metrics at /metrics (Prometheus text format)\n", "text/plain; charset=utf-8");
  });
  if (!impl.http.bind_to_port(options.address, options.port))
    throw InvalidArgument(fmt::format("--metrics-port {}: cannot listen on {} port {}: {}", options.port,
                                      options.address, options.port,
                                      cli::listen_problem(options.address, options.port)));
  impl.thread = std::thread([&impl] { impl.http.listen_after_bind(); });
  // httplib's stop() is lost on a server not listening yet: the destructor may come at once (a run refused at start).
  for (int i = 0; i < 5000 && !impl.http.is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

MetricsServer::~MetricsServer() {
  impl_->http.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

void MetricsServer::publish(std::shared_ptr<const MetricsSnapshot> snapshot) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->latest.swap(snapshot);  // the previous one is freed with `snapshot`, after the lock is released
}

std::shared_ptr<const MetricsSnapshot> MetricsServer::latest() const { return impl_->current(); }

std::uint64_t MetricsServer::scrapes() const { return impl_->scrapes.load(); }

int MetricsServer::port() const { return impl_->options.port; }

}  // namespace marsala::world_server
