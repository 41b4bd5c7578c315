// NavigabilityProcessor speed: the robot of the paper's experiments (delta 1 m, kappa 0.3, eps 0.05 m) on
// 0.1 m cells, i.e. a ball of radius 5 cells and pairs up to 10 cells apart.
//   smooth: seeded value-noise fBm with a few metres of relief, plus straight cliffs and single-cell spikes;
//   rough:  uniform noise, 0 .. 0.5 m per cell (nearly nothing occupiable: the worst case for candidates);
//   steep ramp: a plane at slope 0.36 along a diagonal, where only far-apart pairs violate.
// The brute-force reference runs beside the fast processor at 128^2 and 256^2 so the speed-up is measured in
// the same run. BM_PeakMemory reports the peak resident memory an occupiable() call adds, per cell.

#include <benchmark/benchmark.h>
#include <malloc.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <utility>

#include "marsala/core/heightmap.hpp"
#include "marsala/core/navigability_processor.hpp"
#include "marsala/terrain/generators.hpp"
#include "support/navigability_brute_force.hpp"

namespace {

using marsala::GridGeometry;
using marsala::Heightmap;
using marsala::NavigabilityParams;
using marsala::NavigabilityProcessor;

constexpr double kCellSizeM = 0.1;
const NavigabilityParams kRobot{0.3, 1.0, 0.05};

std::uint64_t mix(std::uint64_t x) {  // splitmix64 finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Lattice value in [-1, 1] at integer point (x, y) of octave `octave`.
double lattice(std::uint64_t seed, int octave, long long x, long long y) {
  const std::uint64_t h = mix(seed ^ mix(static_cast<std::uint64_t>(octave) ^
                                         mix(static_cast<std::uint64_t>(x) ^ mix(static_cast<std::uint64_t>(y)))));
  return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

/// Smoothstep-interpolated value noise at (x, y) in lattice units, in [-1, 1].
double value_noise(std::uint64_t seed, int octave, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const long long ix = static_cast<long long>(fx), iy = static_cast<long long>(fy);
  const double tx = x - fx, ty = y - fy;
  const double sx = tx * tx * (3.0 - 2.0 * tx), sy = ty * ty * (3.0 - 2.0 * ty);
  const double top =
      lattice(seed, octave, ix, iy) + sx * (lattice(seed, octave, ix + 1, iy) - lattice(seed, octave, ix, iy));
  const double bottom = lattice(seed, octave, ix, iy + 1) +
                        sx * (lattice(seed, octave, ix + 1, iy + 1) - lattice(seed, octave, ix, iy + 1));
  return top + sy * (bottom - top);
}

/// fBm (5 octaves from a 40 m wavelength, 1.5 m amplitude, gain 0.5) + 3 cliffs of 0.8..2 m + spikes
/// (one cell in 2000 raised 0.3..1.2 m) on an n x n grid of 0.1 m cells [m].
Heightmap smooth_terrain(int n, std::uint64_t seed) {
  Heightmap h(GridGeometry{n, n, 0.0, 0.0, kCellSizeM}, 0.0);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const double x = c * kCellSizeM, y = r * kCellSizeM;
      double height = 0.0, amplitude = 1.5, wavelength = 40.0;
      for (int octave = 0; octave < 5; ++octave, amplitude *= 0.5, wavelength *= 0.5)
        height += amplitude * value_noise(seed, octave, x / wavelength, y / wavelength);
      h(r, c) = height;
    }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int cliff = 0; cliff < 3; ++cliff) {
    const double angle = 6.283185307179586 * unit(rng), offset = (unit(rng) - 0.5) * n * 0.6;
    const double rise = 0.8 + 1.2 * unit(rng);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c)
        if (std::cos(angle) * (c - n / 2.0) + std::sin(angle) * (r - n / 2.0) > offset) h(r, c) += rise;
  }
  std::uniform_int_distribution<int> cell(0, n - 1);
  for (long long spike = 0; spike < static_cast<long long>(n) * n / 2000; ++spike)
    h(cell(rng), cell(rng)) += 0.3 + 0.9 * unit(rng);
  return h;
}

/// Uniform noise in [0, 0.5] m per cell on an n x n grid of 0.1 m cells.
Heightmap rough_terrain(int n, std::uint64_t seed) {
  Heightmap h(GridGeometry{n, n, 0.0, 0.0, kCellSizeM}, 0.0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 0.5);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) h(r, c) = u(rng);
  return h;
}

/// A plane at slope 0.36 (kappa + 0.06) along the diagonal: only pairs 9 or more cells apart violate.
Heightmap steep_ramp(int n, std::uint64_t) {
  Heightmap h(GridGeometry{n, n, 0.0, 0.0, kCellSizeM}, 0.0);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) h(r, c) = 0.36 * (c + r) * kCellSizeM / std::sqrt(2.0);
  return h;
}

/// The project's `mix` generator at its default parameters (fractal, hills, craters, cliffs).
Heightmap generated_mix(int n, std::uint64_t seed) {
  marsala::terrain::GeneratorSpec spec;
  spec.rows = spec.cols = n;
  spec.cell_size_m = kCellSizeM;
  spec.seed = seed;
  return marsala::terrain::generate_terrain("mix", spec);
}

using Generator = Heightmap (*)(int, std::uint64_t);

const Heightmap& terrain(Generator make, int n) {
  static std::map<std::pair<Generator, int>, Heightmap> cache;
  auto it = cache.find({make, n});
  if (it == cache.end()) it = cache.emplace(std::make_pair(make, n), make(n, 42)).first;
  return it->second;
}

double occupiable_fraction(const marsala::CellMask& mask) {
  long long n = 0;
  for (Eigen::Index i = 0; i < mask.size(); ++i) n += mask.data()[i];
  return static_cast<double>(n) / static_cast<double>(mask.size());
}

void run_fast(benchmark::State& state, Generator make) {
  const Heightmap& h = terrain(make, static_cast<int>(state.range(0)));
  const NavigabilityProcessor processor(kRobot);
  double fraction = 0.0;
  for (auto _ : state) {
    const auto mask = processor.occupiable(h);
    benchmark::DoNotOptimize(mask.data());
    fraction = occupiable_fraction(mask);
  }
  state.counters["occupiable"] = fraction;
  state.counters["cells_per_s"] =
      benchmark::Counter(static_cast<double>(h.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void run_brute(benchmark::State& state, Generator make) {
  const Heightmap& h = terrain(make, static_cast<int>(state.range(0)));
  double fraction = 0.0;
  for (auto _ : state) {
    const auto mask = marsala::testing::occupiable_brute_force(h, kRobot);
    benchmark::DoNotOptimize(mask.data());
    fraction = occupiable_fraction(mask);
  }
  state.counters["occupiable"] = fraction;
}

void BM_OccupiableSmooth(benchmark::State& state) { run_fast(state, smooth_terrain); }
void BM_OccupiableSmoothBruteForce(benchmark::State& state) { run_brute(state, smooth_terrain); }
void BM_OccupiableRough(benchmark::State& state) { run_fast(state, rough_terrain); }
void BM_OccupiableGeneratedMix(benchmark::State& state) { run_fast(state, generated_mix); }
void BM_OccupiableGeneratedMixBruteForce(benchmark::State& state) { run_brute(state, generated_mix); }
void BM_OccupiableRoughBruteForce(benchmark::State& state) { run_brute(state, rough_terrain); }
void BM_OccupiableSteepRamp(benchmark::State& state) { run_fast(state, steep_ramp); }

void BM_NavigableSmooth(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const Heightmap& h = terrain(smooth_terrain, n);
  const NavigabilityProcessor processor(kRobot);
  const auto occupiable = processor.occupiable(h);
  // Start from the occupiable cell nearest the centre, scanning outwards along the middle row.
  marsala::CellIndex origin{n / 2, n / 2};
  for (int d = 0; d < n / 2 && occupiable(origin.row, origin.col) == 0; ++d) origin.col = n / 2 + d;
  double fraction = 0.0;
  for (auto _ : state) {
    const auto mask = processor.navigable(h, origin);
    benchmark::DoNotOptimize(mask.data());
    fraction = occupiable_fraction(mask);
  }
  state.counters["navigable"] = fraction;
}

/// Resident memory of this process [bytes], from /proc/self/status (`field`: VmRSS or VmHWM).
double resident_bytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string key;
  double kb = 0.0;
  while (status >> key) {
    if (key == field + ":") {
      status >> kb;
      return kb * 1024.0;
    }
    status.ignore(1 << 20, '\n');
  }
  return -1.0;
}

/// Peak resident memory added by one occupiable() (or navigable()) call on the smooth terrain, per cell:
/// free heap is returned to the system first, then the peak counter (VmHWM) is reset via /proc/self/clear_refs.
void BM_PeakMemory(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const bool navigable = state.range(1) != 0;
  const Heightmap& h = terrain(smooth_terrain, n);
  const NavigabilityProcessor processor(kRobot);
  double extra = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    malloc_trim(0);
    std::ofstream("/proc/self/clear_refs") << "5";
    const double before = resident_bytes("VmRSS");
    state.ResumeTiming();
    {
      const auto mask = navigable ? processor.navigable(h, {n / 2, n / 2}) : processor.occupiable(h);
      benchmark::DoNotOptimize(mask.data());
    }
    state.PauseTiming();
    extra = resident_bytes("VmHWM") - before;
    state.ResumeTiming();
  }
  state.counters["peak_extra_B_per_cell"] = extra / static_cast<double>(h.size());
}

BENCHMARK(BM_OccupiableSmooth)->Arg(128)->Arg(256)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OccupiableSmoothBruteForce)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OccupiableGeneratedMix)->Arg(256)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OccupiableGeneratedMixBruteForce)->Arg(256)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OccupiableRough)->Arg(128)->Arg(256)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OccupiableRoughBruteForce)->Arg(128)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OccupiableSteepRamp)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NavigableSmooth)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PeakMemory)->Args({2048, 0})->Args({2048, 1})->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
