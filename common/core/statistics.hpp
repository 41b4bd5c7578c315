#pragma once
// Order statistics of measured timings, as every report of the project computes them (world steps, agent decisions,
// benchmarks): one definition, so a median means the same number everywhere.

#include <algorithm>
#include <utility>
#include <cstddef>
#include <vector>

namespace marsala {

/// The q-quantile of `values` by nearest rank, element floor(q * (n - 1) + 0.5) of the sorted values (so the median
/// of an even count is the upper middle one); 0 when empty. Takes a copy: the caller's order is kept.
inline double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/// percentile(values, 0.5).
inline double median(std::vector<double> values) { return percentile(std::move(values), 0.5); }

}  // namespace marsala
