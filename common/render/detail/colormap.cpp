#include "marsala/render/detail/colormap.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace marsala::render::detail {
namespace {

struct Stop {
  double t;
  Colour c;
};

template <std::size_t N>
Colour interpolate(const Stop (&stops)[N], double t) {
  if (!(t > 0.0)) return stops[0].c;
  if (t >= 1.0) return stops[N - 1].c;
  std::size_t i = 1;
  while (i < N - 1 && stops[i].t < t) ++i;
  const double a = (t - stops[i - 1].t) / (stops[i].t - stops[i - 1].t);
  return mix(stops[i - 1].c, stops[i].c, a);
}

// Lightness increases monotonically, so the map reads correctly in greyscale and for colour-blind readers;
// blue-to-sand avoids the green and red used by the navigability and gap overlays.
constexpr Stop kTerrain[] = {
    {0.00, {44, 52, 102}},   {0.15, {50, 76, 126}},   {0.32, {68, 106, 144}},  {0.50, {112, 140, 152}},
    {0.66, {162, 160, 144}}, {0.80, {205, 180, 142}}, {0.92, {234, 211, 182}}, {1.00, {250, 243, 233}},
};

constexpr Stop kHeat[] = {
    {0.00, {255, 236, 120}}, {0.30, {252, 170, 60}}, {0.60, {232, 88, 40}},
    {0.85, {180, 30, 40}},   {1.00, {110, 10, 40}},
};

}  // namespace

Colour terrain_colour(double t) { return interpolate(kTerrain, t); }

Colour heat_colour(double t) { return interpolate(kHeat, t); }

}  // namespace marsala::render::detail
