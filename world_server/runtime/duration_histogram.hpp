#pragma once
// A histogram of durations as Prometheus keeps one (docs/runtime.md#metrics): counts per bucket of fixed upper
// bounds, their sum and count. Plain data, copied into every metrics snapshot.

#include <cstdint>
#include <vector>

namespace marsala::world_server {

/// The bounds of the step-time histograms: 0.5 ms to 10 s, about three per decade [s].
const std::vector<double>& step_duration_bounds_s();

/// Durations observed so far, by bucket.
class DurationHistogram {
 public:
  /// Buckets with upper bounds `upper_bounds_s` (ascending, finite), and one for anything above the last [s].
  /// Throws InvalidArgument when the bounds are not strictly ascending and finite.
  explicit DurationHistogram(std::vector<double> upper_bounds_s = step_duration_bounds_s());

  /// Counts one duration [s] in the first bucket whose bound it does not exceed (a NaN is not counted).
  void observe(double seconds);

  /// The buckets' upper bounds, ascending, without the last bucket's +Inf [s].
  const std::vector<double>& upper_bounds_s() const { return bounds_s_; }
  /// Observations in each bucket, not cumulative; one more entry than upper_bounds_s() (the +Inf bucket) [count].
  const std::vector<std::uint64_t>& bucket_counts() const { return counts_; }
  /// The sum of every observation [s].
  double sum_s() const { return sum_s_; }
  /// Observations [count].
  std::uint64_t count() const { return count_; }

 private:
  std::vector<double> bounds_s_;
  std::vector<std::uint64_t> counts_;
  double sum_s_ = 0.0;
  std::uint64_t count_ = 0;
};

}  // namespace marsala::world_server
