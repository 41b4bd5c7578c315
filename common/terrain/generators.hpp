#pragma once
// Seeded terrain generators chosen by name (registry filled by register_builtins() in generators.cpp).
//
// Every generator returns a rows x cols Heightmap [m] with its lower-left corner at (0, 0). Length defaults
// scale with the map extent E = max(rows, cols) * cell_size_m [m], so that, e.g., a 1024 x 1024 grid of
// 0.1 m cells gets a few metres of relief. Same spec -> same heights, bit for bit: generators use only
// splitmix64 and their own conversions and elementary functions, never the standard distributions.
//
// Methods and their height ranges (n = count, H = height parameter):
//   flat            height everywhere
//   platform        0 on the ground, `height` on the box
//   ramp            [0, slope * extent along the azimuth]; lowest cell centre at 0
//   gaussian_hills  [0, count * amplitude]
//   fractal         spans exactly [-amplitude, amplitude] (0 on a single cell)
//   craters         [-count * depth, count * rim_height]
//   steps           [min(0, n H), max(0, n H)]
//   mix             fractal + gaussian_hills + craters + steps with the mix's amplitudes

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "marsala/core/heightmap.hpp"

namespace marsala::terrain {

/// What every generator gets: grid size, cell size [m], seed, and named numeric parameters (metres unless said).
struct GeneratorSpec {
  int rows = 256;
  int cols = 256;
  double cell_size_m = 0.1;
  std::uint64_t seed = 1;
  std::map<std::string, double> params;  ///< method-specific; unknown keys are an error listing the valid ones
};

/// Generates a terrain by method name; throws InvalidArgument for an unknown method (listing the valid names), an
/// unknown parameter key (listing the method's keys) or an out-of-range value (saying which and the range).
/// Lower-left corner at (0, 0). Deterministic: same spec -> same heights bit for bit.
Heightmap generate_terrain(const std::string& method, const GeneratorSpec& spec);

/// The registered method names, sorted.
std::vector<std::string> generator_names();

/// One line per parameter of `method`: "key (default D): meaning [unit]" for --help texts; throws
/// InvalidArgument for an unknown method.
std::vector<std::string> generator_parameter_help(const std::string& method);

}  // namespace marsala::terrain
