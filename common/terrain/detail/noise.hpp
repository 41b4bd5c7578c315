#pragma once
// Seeded noise fields for the terrain generators; deterministic bit for bit (see random.hpp, det_math.hpp).

#include <cstdint>

#include "marsala/core/heightmap.hpp"

namespace marsala::terrain::detail {

/// Fractional Brownian motion of 2D gradient noise sampled at the cell centres of a grid whose lower-left
/// corner is (0, 0): octave o has wavelength base_wavelength_m / 2^o and weight persistence^o. Octaves after
/// the first whose wavelength is below two cells are skipped. Values are unnormalised (roughly [-1, 1] times
/// the sum of the weights). Requires base_wavelength_m >= cell_size_m.
HeightMatrix gradient_fbm(int rows, int cols, double cell_size_m, std::uint64_t seed, int octaves, double persistence,
                          double base_wavelength_m);

/// Smooth 1D value noise in [-1, 1] with the given wavelength [m], for wavy lines (cliff edges).
class ValueNoise1d {
 public:
  ValueNoise1d(std::uint64_t seed, double wavelength_m);
  /// Noise value at abscissa t [m].
  double operator()(double t_m) const;

 private:
  std::uint64_t seed_;
  double inv_wavelength_;
  double offset_;
};

/// Quintic fade 6t^5 - 15t^4 + 10t^3: 0 at 0, 1 at 1, zero first and second derivatives at both ends.
inline double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

}  // namespace marsala::terrain::detail
