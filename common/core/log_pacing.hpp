#pragma once
// Bounded logging of repeated things (refusals, forged requests, ignored frames): a line at the 1st, 10th, 100th,
// ... occurrence, each carrying the count so far, so a flood stays a few lines.

#include <cstdint>

namespace marsala {

/// True when `n` is 1, 10, 100, ...
inline bool power_of_ten(std::uint64_t n) {
  while (n >= 10 && n % 10 == 0) n /= 10;
  return n == 1;
}

}  // namespace marsala
