#include "common/processing/goal_vector_map.hpp"

#include "common/error.hpp"

namespace marsala::processing {

std::string to_string(Heading heading) {
  switch (heading) {
    case Heading::kEast: return "east";
    case Heading::kWest: return "west";
    case Heading::kNorth: return "north";
    case Heading::kSouth: return "south";
  }
  return "unknown";
}

Heading heading_from_string(const std::string& name) {
  for (Heading h : {Heading::kEast, Heading::kWest, Heading::kNorth, Heading::kSouth})
    if (to_string(h) == name) return h;
  throw InvalidArgument("unknown heading '" + name + "'; valid: east, west, north, south");
}

GoalVectorMap::GoalVectorMap(const GoalVectorMapSpec& spec, const grid::GridGeometry& /*grid*/) : spec_(spec) {}

std::optional<std::size_t> GoalVectorMap::nearest_free_tail(Position, const std::vector<bool>&) const {
  return std::nullopt;
}

std::optional<std::size_t> GoalVectorMap::next(std::size_t) const { return std::nullopt; }

}  // namespace marsala::processing
