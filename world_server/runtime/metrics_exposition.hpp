#pragma once
// The Prometheus text exposition format (version 0.0.4) of a metrics snapshot: the metric families of
// docs/runtime.md#metrics, each with its HELP and TYPE lines. Pure: a string from a value.

#include <string>

#include "marsala/world_server/runtime/metrics_snapshot.hpp"

namespace marsala::world_server {

/// The content type of render_metrics()'s text, for an HTTP response.
inline constexpr const char* kMetricsContentType = "text/plain; version=0.0.4; charset=utf-8";

/// `snapshot` in the Prometheus text format: every family of docs/runtime.md#metrics, in that order, numbers in
/// their shortest round-trip form, label values escaped; ends with a newline.
std::string render_metrics(const MetricsSnapshot& snapshot);

/// The world process's own numbers, read when a scrape comes (not part of a step's snapshot).
struct ProcessMetrics {
  double cpu_seconds = 0.0;           ///< CPU time of every thread so far [s]
  double resident_memory_bytes = 0.0;  ///< resident set size [bytes]
  double start_time_seconds = 0.0;    ///< when the process started, since the Unix epoch [s]
};

/// The standard process families of Prometheus clients: process_cpu_seconds_total, process_resident_memory_bytes,
/// process_start_time_seconds, in the text format.
std::string render_process_metrics(const ProcessMetrics& process);

}  // namespace marsala::world_server
