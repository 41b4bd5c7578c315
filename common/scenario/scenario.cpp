#include "marsala/scenario/scenario.hpp"

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala::scenario {

const RobotType& Scenario::robot_for(std::uint32_t id) const {
  if (id == 0 || id > slots.size())
    throw InvalidArgument(fmt::format("scenario '{}' has no agent slot {} (slots 1..{})", name, id, slots.size()));
  const std::string& type = slots[id - 1].robot_type;
  for (const RobotType& t : robot_types)
    if (t.name == type) return t;
  throw InvalidArgument(fmt::format("scenario '{}': agent slot {} names unknown robot type '{}'", name, id, type));
}

}  // namespace marsala::scenario
