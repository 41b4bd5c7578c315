#include "marsala/world_server/runtime/duration_histogram.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "marsala/core/error.hpp"

namespace marsala::world_server {

const std::vector<double>& step_duration_bounds_s() {
  // A ramp step takes a few ms, a crowd's tens of ms, a step held for a dead agent its deadline (10 s by default).
  static const std::vector<double> bounds{0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05,
                                          0.1,    0.2,   0.5,   1.0,   2.0,  5.0,  10.0};
  return bounds;
}

DurationHistogram::DurationHistogram(std::vector<double> upper_bounds_s)
    : bounds_s_(std::move(upper_bounds_s)), counts_(bounds_s_.size() + 1, 0) {
  for (std::size_t i = 0; i < bounds_s_.size(); ++i)
    if (!std::isfinite(bounds_s_[i]) || (i > 0 && !(bounds_s_[i] > bounds_s_[i - 1])))
      throw InvalidArgument("histogram bounds must be finite and strictly ascending");
}

void DurationHistogram::observe(double seconds) {
  if (std::isnan(seconds)) return;
  const auto bucket = std::lower_bound(bounds_s_.begin(), bounds_s_.end(), seconds) - bounds_s_.begin();
  ++counts_[static_cast<std::size_t>(bucket)];
  sum_s_ += seconds;
  ++count_;
}

}  // namespace marsala::world_server
