#include "marsala/terrain/detail/noise.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "marsala/core/random.hpp"
#include "marsala/terrain/detail/det_math.hpp"

namespace marsala::terrain::detail {
namespace {

using random::derive_seed;
using random::hash2;
using random::Rng;
using random::to_unit;

// Sixteen unit gradients, k * 22.5 degrees, as literals (no libm involved).
constexpr double kC1 = 0.92387953251128674;  // cos 22.5
constexpr double kC2 = 0.70710678118654752;  // cos 45
constexpr double kC3 = 0.38268343236508977;  // cos 67.5
constexpr double kGradX[16] = {1, kC1, kC2, kC3, 0, -kC3, -kC2, -kC1, -1, -kC1, -kC2, -kC3, 0, kC3, kC2, kC1};
constexpr double kGradY[16] = {0, kC3, kC2, kC1, 1, kC1, kC2, kC3, 0, -kC3, -kC2, -kC1, -1, -kC1, -kC2, -kC3};

// floor() as an integer without a libm call (exact for |x| < 2^62).
inline std::int64_t floor_to_int(double x) {
  const auto i = static_cast<std::int64_t>(x);
  return static_cast<double>(i) > x ? i - 1 : i;
}

void add_octave(HeightMatrix& out, double cell_size_m, std::uint64_t seed, double wavelength_m, double amplitude) {
  const int rows = static_cast<int>(out.rows());
  const int cols = static_cast<int>(out.cols());
  Rng rng(seed);
  // Each octave gets its own rotation and lattice offset, so lattice-aligned artefacts of different octaves
  // do not line up with each other or with the grid axes.
  const double angle = rng.uniform(0.0, 360.0);
  const double off_u = rng.uniform(0.0, 4096.0);
  const double off_v = rng.uniform(0.0, 4096.0);
  const double inv = 1.0 / wavelength_m;
  const double cu = det_cos_deg(angle) * inv, su = det_sin_deg(angle) * inv;
  // Lattice coordinates: u = cu x + su y + off_u, v = -su x + cu y + off_v, split into column and row parts.
  std::vector<double> col_u(cols), col_v(cols), row_u(rows), row_v(rows);
  for (int c = 0; c < cols; ++c) {
    const double x = (c + 0.5) * cell_size_m;
    col_u[c] = cu * x;
    col_v[c] = -su * x;
  }
  for (int r = 0; r < rows; ++r) {
    const double y = (rows - r - 0.5) * cell_size_m;  // row 0 is northmost
    row_u[r] = su * y + off_u;
    row_v[r] = cu * y + off_v;
  }
  // Lattice cells touched by the grid: bounded by the extreme column and row terms.
  const auto [cu_lo, cu_hi] = std::minmax_element(col_u.begin(), col_u.end());
  const auto [cv_lo, cv_hi] = std::minmax_element(col_v.begin(), col_v.end());
  const auto [ru_lo, ru_hi] = std::minmax_element(row_u.begin(), row_u.end());
  const auto [rv_lo, rv_hi] = std::minmax_element(row_v.begin(), row_v.end());
  const auto i0 = static_cast<std::int64_t>(std::floor(*cu_lo + *ru_lo)) - 1;
  const auto j0 = static_cast<std::int64_t>(std::floor(*cv_lo + *rv_lo)) - 1;
  const auto ni = static_cast<std::size_t>(static_cast<std::int64_t>(std::floor(*cu_hi + *ru_hi)) - i0 + 3);
  const auto nj = static_cast<std::size_t>(static_cast<std::int64_t>(std::floor(*cv_hi + *rv_hi)) - j0 + 3);
  std::vector<std::uint8_t> grad(ni * nj);
  for (std::size_t j = 0; j < nj; ++j)
    for (std::size_t i = 0; i < ni; ++i)
      grad[j * ni + i] = static_cast<std::uint8_t>(
          hash2(seed, i0 + static_cast<std::int64_t>(i), j0 + static_cast<std::int64_t>(j)) >> 60);

  for (int r = 0; r < rows; ++r) {
    double* row = out.data() + static_cast<std::size_t>(r) * cols;
    for (int c = 0; c < cols; ++c) {
      const double u = col_u[c] + row_u[r];
      const double v = col_v[c] + row_v[r];
      const std::int64_t iu = floor_to_int(u), iv = floor_to_int(v);
      const double fx = u - static_cast<double>(iu), fy = v - static_cast<double>(iv);
      const std::size_t i = static_cast<std::size_t>(iu - i0);
      const std::size_t j = static_cast<std::size_t>(iv - j0);
      const std::uint8_t* g0 = &grad[j * ni + i];
      const std::uint8_t* g1 = g0 + ni;
      const double n00 = kGradX[g0[0]] * fx + kGradY[g0[0]] * fy;
      const double n10 = kGradX[g0[1]] * (fx - 1.0) + kGradY[g0[1]] * fy;
      const double n01 = kGradX[g1[0]] * fx + kGradY[g1[0]] * (fy - 1.0);
      const double n11 = kGradX[g1[1]] * (fx - 1.0) + kGradY[g1[1]] * (fy - 1.0);
      const double sx = fade(fx);
      const double a = n00 + sx * (n10 - n00);
      const double b = n01 + sx * (n11 - n01);
      row[c] += amplitude * (a + fade(fy) * (b - a));
    }
  }
}

}  // namespace

HeightMatrix gradient_fbm(int rows, int cols, double cell_size_m, std::uint64_t seed, int octaves, double persistence,
                          double base_wavelength_m) {
  HeightMatrix out = HeightMatrix::Zero(rows, cols);
  double wavelength = base_wavelength_m;
  double amplitude = 1.0;
  for (int o = 0; o < octaves; ++o) {
    if (o > 0 && wavelength < 2.0 * cell_size_m) break;
    add_octave(out, cell_size_m, derive_seed(seed, static_cast<std::uint64_t>(o)), wavelength, amplitude);
    wavelength *= 0.5;
    amplitude *= persistence;
  }
  return out;
}

ValueNoise1d::ValueNoise1d(std::uint64_t seed, double wavelength_m)
    : seed_(seed), inv_wavelength_(1.0 / wavelength_m), offset_(Rng(seed).uniform(0.0, 4096.0)) {}

double ValueNoise1d::operator()(double t_m) const {
  const double u = t_m * inv_wavelength_ + offset_;
  const double fl = std::floor(u);
  const auto i = static_cast<std::int64_t>(fl);
  const double a = 2.0 * to_unit(hash2(seed_, i, 0)) - 1.0;
  const double b = 2.0 * to_unit(hash2(seed_, i + 1, 0)) - 1.0;
  return a + fade(u - fl) * (b - a);
}

}  // namespace marsala::terrain::detail
