// MARS processor benchmarks: generated terrain at several sizes, three adversarial inputs, and the
// brute-force reference at small sizes so that speed-ups are measured in the same run.
// Cell size 0.1 m, kappa 0.3. Counters: cells, CPU ns per cell, and peak scratch memory of project() in bytes per
// cell (operator new, i.e. every std::vector inside; the 8-byte output matrix is allocated by Eigen
// with malloc and is reported separately as output_B_per_cell).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <new>
#include <random>
#include <vector>

#include "marsala/core/cpu_time.hpp"
#include "marsala/core/heightmap.hpp"
#include "marsala/core/mars_processor.hpp"
#include "marsala/terrain/generators.hpp"
#include "support/mars_brute_force.hpp"

// ---- allocation counting (global operator new / delete) ------------------------------------

namespace {
std::atomic<long long> g_live_bytes{0};
std::atomic<long long> g_peak_bytes{0};

void* counted_alloc(std::size_t size) {
  void* raw = std::malloc(size + 16);
  if (!raw) throw std::bad_alloc();
  *static_cast<std::size_t*>(raw) = size;
  const long long live = g_live_bytes += static_cast<long long>(size);
  long long peak = g_peak_bytes.load();
  while (live > peak && !g_peak_bytes.compare_exchange_weak(peak, live)) {
  }
  return static_cast<char*>(raw) + 16;
}

void counted_free(void* p) {
  if (!p) return;
  void* raw = static_cast<char*>(p) - 16;
  g_live_bytes -= static_cast<long long>(*static_cast<std::size_t*>(raw));
  std::free(raw);
}
}  // namespace

void* operator new(std::size_t size) { return counted_alloc(size); }
void* operator new[](std::size_t size) { return counted_alloc(size); }
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }

namespace {

using marsala::GridGeometry;
using marsala::Heightmap;
using marsala::thread_cpu_ms;
using marsala::MarsProcessor;

constexpr double kCellM = 0.1;
constexpr double kKappa = 0.3;

// ---- inputs --------------------------------------------------------------------------------

// Seeded rough terrain: fBm value noise (6 octaves, ~4 m of relief), three straight cliffs of
// 1-1.5 m and 40 single-cell spikes of 1-4 m.
Heightmap make_rough_terrain(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Heightmap h(GridGeometry{n, n, 0.0, 0.0, kCellM}, 0.0);
  double amplitude = 2.0;
  for (int period = 256; period >= 8; period /= 2, amplitude *= 0.5) {
    const int lattice_n = n / period + 2;
    std::vector<double> lattice(static_cast<std::size_t>(lattice_n) * lattice_n);
    for (double& v : lattice) v = amplitude * u(rng);
    auto at = [&](int a, int b) { return lattice[static_cast<std::size_t>(a) * lattice_n + b]; };
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        const double fr = static_cast<double>(r) / period, fc = static_cast<double>(c) / period;
        const int ir = static_cast<int>(fr), ic = static_cast<int>(fc);
        const double tr = (fr - ir) * (fr - ir) * (3 - 2 * (fr - ir)), tc = (fc - ic) * (fc - ic) * (3 - 2 * (fc - ic));
        h(r, c) += (1 - tr) * ((1 - tc) * at(ir, ic) + tc * at(ir, ic + 1)) +
                   tr * ((1 - tc) * at(ir + 1, ic) + tc * at(ir + 1, ic + 1));
      }
  }
  for (int k = 0; k < 3; ++k) {
    const double angle = 2 * M_PI * u(rng), offset = (u(rng) - 0.5) * n * 0.6, step = 1.0 + 0.5 * u(rng);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c)
        if ((c - n / 2) * std::cos(angle) + (r - n / 2) * std::sin(angle) > offset) h(r, c) += step;
  }
  for (int k = 0; k < 40; ++k) h(static_cast<int>(u(rng) * n), static_cast<int>(u(rng) * n)) += 1.0 + 3.0 * u(rng);
  return h;
}

// Six cones of slope exactly kappa with apexes anywhere (not on cell centres).
Heightmap make_exact_cones(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Heightmap h(GridGeometry{n, n, 0.0, 0.0, kCellM}, -1e300);
  for (int k = 0; k < 6; ++k) {
    const double ax = u(rng) * n * kCellM, ay = u(rng) * n * kCellM, top = 5.0 + 15.0 * u(rng);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        const marsala::Position p = h.cell_center({r, c});
        h(r, c) = std::max(h(r, c), top - kKappa * std::hypot(p.x - ax, p.y - ay));
      }
  }
  return h;
}

// h = slope_factor kappa (x cos 30deg + y sin 30deg); at slope_factor 1 every cell is an
// undominated source and near-ties are everywhere.
Heightmap make_plane(int n, double slope_factor) {
  Heightmap h(GridGeometry{n, n, 0.0, 0.0, kCellM}, 0.0);
  const double a = M_PI / 6;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const marsala::Position p = h.cell_center({r, c});
      h(r, c) = slope_factor * kKappa * (p.x * std::cos(a) + p.y * std::sin(a));
    }
  return h;
}

// A roof: two planes of slope exactly kappa meeting at a crest at an irrational angle.
Heightmap make_roof(int n) {
  Heightmap h(GridGeometry{n, n, 0.0, 0.0, kCellM}, 0.0);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const marsala::Position p = h.cell_center({r, c});
      h(r, c) = 20.0 - kKappa * std::abs(0.6 * p.x - 0.8 * p.y + 3.3);
    }
  return h;
}

// The project's own generators at their default parameters (relief scales with the map: at 1024^2 of 0.1 m
// cells the fractal spans about +-2.6 m).
Heightmap make_generated(const char* method, int n) {
  marsala::terrain::GeneratorSpec spec;
  spec.rows = spec.cols = n;
  spec.cell_size_m = kCellM;
  spec.seed = 2024;
  return marsala::terrain::generate_terrain(method, spec);
}

enum class Input { kTerrain, kFedBack, kCones, kPlane, kRoof, kSteepPlane, kMix, kFractal };

const Heightmap& input(Input kind, int n) {
  static std::map<std::pair<int, int>, Heightmap> cache;
  const auto key = std::make_pair(static_cast<int>(kind), n);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  Heightmap h;
  switch (kind) {
    case Input::kTerrain: h = make_rough_terrain(n, 2024); break;
    case Input::kFedBack: h = MarsProcessor(kKappa).project(make_rough_terrain(n, 2024)); break;
    case Input::kCones: h = make_exact_cones(n, 7); break;
    case Input::kPlane: h = make_plane(n, 1.0); break;
    case Input::kRoof: h = make_roof(n); break;
    case Input::kSteepPlane: h = make_plane(n, 1.001); break;
    case Input::kMix: h = make_generated("mix", n); break;
    case Input::kFractal: h = make_generated("fractal", n); break;
  }
  return cache.emplace(key, std::move(h)).first->second;
}

// ---- benchmarks ----------------------------------------------------------------------------

void run_fast(benchmark::State& state, Input kind) {
  const int n = static_cast<int>(state.range(0));
  const Heightmap& h = input(kind, n);
  const MarsProcessor mars(kKappa);
  long long scratch_peak = 0;
  double cpu_ms = 0;
  for (auto _ : state) {
    const long long before = g_live_bytes.load();
    g_peak_bytes = before;
    const double start_ms = thread_cpu_ms();
    Heightmap p = mars.project(h);
    cpu_ms += thread_cpu_ms() - start_ms;
    scratch_peak = std::max(scratch_peak, g_peak_bytes.load() - before);
    benchmark::DoNotOptimize(p.data());
  }
  state.counters["cells"] = static_cast<double>(h.size());
  // CPU nanoseconds per cell and projection: the growth from 256^2 to 4096^2 shows how far from linear the solve is.
  state.counters["ns_per_cell"] = 1e6 * cpu_ms / static_cast<double>(state.iterations()) / static_cast<double>(h.size());
  state.counters["scratch_B_per_cell"] = static_cast<double>(scratch_peak) / h.size();
  state.counters["output_B_per_cell"] = sizeof(double);
}

void run_brute(benchmark::State& state, Input kind) {
  const int n = static_cast<int>(state.range(0));
  const Heightmap& h = input(kind, n);
  for (auto _ : state) {
    Heightmap p = marsala::testing::mars_brute_force(h, kKappa);
    benchmark::DoNotOptimize(p.data());
  }
  state.counters["cells"] = static_cast<double>(h.size());
}

// An agent's local window (41 x 41 cells: a 5 m sensing range on 0.25 m cells in the shipped scenarios), one per
// iteration, sliding a cell at a time over a 256^2 input as a driving robot's window does.
void run_window(benchmark::State& state, Input kind) {
  constexpr int kSide = 41, kSpan = 256 - kSide;
  const Heightmap& h = input(kind, 256);
  const MarsProcessor mars(kKappa);
  int at = 0;
  for (auto _ : state) {
    const marsala::CellIndex corner{(at / kSpan) % kSpan, at % kSpan};
    ++at;
    Heightmap p = mars.project(h.window(corner, kSide, kSide));
    benchmark::DoNotOptimize(p.data());
  }
  state.counters["cells"] = kSide * kSide;
}

// Required cases: terrain at several sizes; adversarial (a) MARS output fed back, (b) cones of
// slope exactly kappa with apexes anywhere, (c) a plane of slope exactly kappa at 30 degrees.
void BM_MarsTerrain(benchmark::State& state) { run_fast(state, Input::kTerrain); }
void BM_MarsGeneratedMix(benchmark::State& state) { run_fast(state, Input::kMix); }
void BM_MarsGeneratedFractal(benchmark::State& state) { run_fast(state, Input::kFractal); }
void BM_MarsFedBack(benchmark::State& state) { run_fast(state, Input::kFedBack); }
void BM_MarsCones(benchmark::State& state) { run_fast(state, Input::kCones); }
void BM_MarsPlane30(benchmark::State& state) { run_fast(state, Input::kPlane); }
// More inputs: a crease of two slope-kappa planes, and the known slow case of a plane 0.1% steeper
// than kappa.
void BM_MarsRoof(benchmark::State& state) { run_fast(state, Input::kRoof); }
void BM_MarsSteepPlane(benchmark::State& state) { run_fast(state, Input::kSteepPlane); }
// Local windows of rough terrain and of a built surface (its MARS fed back).
void BM_MarsWindowTerrain(benchmark::State& state) { run_window(state, Input::kTerrain); }
void BM_MarsWindowFedBack(benchmark::State& state) { run_window(state, Input::kFedBack); }
// Brute-force reference at the small sizes, for the speed-up ratio.
void BM_BruteTerrain(benchmark::State& state) { run_brute(state, Input::kTerrain); }
void BM_BruteFedBack(benchmark::State& state) { run_brute(state, Input::kFedBack); }
void BM_BruteCones(benchmark::State& state) { run_brute(state, Input::kCones); }
void BM_BrutePlane30(benchmark::State& state) { run_brute(state, Input::kPlane); }

BENCHMARK(BM_MarsTerrain)->Arg(64)->Arg(128)->Arg(256)->Arg(1024)->Arg(2048)->Unit(benchmark::kMillisecond);
// The generated terrains from 256^2 to 4096^2 (their relief grows with the map), for the time per cell.
BENCHMARK(BM_MarsGeneratedMix)->RangeMultiplier(2)->Range(256, 4096)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarsGeneratedFractal)->RangeMultiplier(2)->Range(256, 4096)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarsFedBack)->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarsCones)->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarsPlane30)->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarsRoof)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarsSteepPlane)->Arg(1024)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarsWindowTerrain)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MarsWindowFedBack)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BruteTerrain)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BruteFedBack)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BruteCones)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BrutePlane30)->Arg(64)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
