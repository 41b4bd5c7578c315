#include "marsala/scenario/scenario.hpp"

#include "marsala/core/error.hpp"

namespace marsala::scenario {

const RobotType& Scenario::robot_for(std::uint32_t id) const {
  if (id == 0 || id > slots.size())
    throw InvalidArgument("scenario '" + name + "' has no agent slot " + std::to_string(id) + " (slots 1.." +
                          std::to_string(slots.size()) + ")");
  const std::string& type = slots[id - 1].robot_type;
  for (const RobotType& t : robot_types)
    if (t.name == type) return t;
  throw InvalidArgument("scenario '" + name + "': agent slot " + std::to_string(id) + " names unknown robot type '" +
                        type + "'");
}

}  // namespace marsala::scenario
