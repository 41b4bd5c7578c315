#pragma once
// Portable pseudo-random numbers (terrain generators, seeded start positions): splitmix64 and exact conversions to
// doubles, so that a seed gives the same numbers bit for bit with every compiler and standard library. Never the
// standard library's distributions, whose results differ between implementations.

#include <cstdint>

namespace marsala::random {

/// The splitmix64 finaliser: a bijective 64-bit mix with good avalanche.
inline std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// A seed for an independent stream, derived from a base seed and a stream tag.
inline std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t tag) {
  return mix64(seed ^ mix64(tag + 0x9e3779b97f4a7c15ULL));
}

/// Hash of a 2D lattice point under a seed.
inline std::uint64_t hash2(std::uint64_t seed, std::int64_t i, std::int64_t j) {
  const std::uint64_t key =
      (static_cast<std::uint64_t>(i) * 0x9e3779b97f4a7c15ULL) ^ (static_cast<std::uint64_t>(j) * 0xc2b2ae3d27d4eb4fULL);
  return mix64(key ^ seed);
}

/// A double in [0, 1) from the top 53 bits of a 64-bit word (exact conversion).
inline double to_unit(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

/// The splitmix64 generator with exact conversions to doubles.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  /// Next 64 random bits.
  std::uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return mix64(state_);
  }
  /// Uniform double in [0, 1).
  double uniform() { return to_unit(next()); }
  /// Uniform double in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

 private:
  std::uint64_t state_;
};

}  // namespace marsala::random
