// marsala-world --check without the bus: this file is built against marsala_world_core alone (tests/CMakeLists.txt),
// which does not link marsala::bus, so it fails to compile or link if the check ever reaches the bus again. (Not
// named *_test.cpp: the world_server part's glob, which links the runtime, leaves it out.)
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include "marsala/world_server/runtime/scenario_check.hpp"

namespace marsala::world_server {
namespace {

std::string shipped(const std::string& name) {
  const char* dir = std::getenv("MARSALA_SOURCE_DIR");
  const std::filesystem::path root = dir ? dir : std::filesystem::path(__FILE__).parent_path() / "../../../..";
  return (root / "deploy" / "scenarios" / name).string();
}

TEST(CheckWithoutBus, TheRampScenarioIsCheckedAsTheWorldWouldStartIt) {
  RuntimeOptions options;
  options.out_dir.clear();
  std::ostringstream out, err;
  EXPECT_EQ(run_scenario_check(shipped("ramp.pbtxt"), options, 7, false, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("ramp"), std::string::npos) << out.str();
  const WorldStart start = check_scenario(shipped("ramp.pbtxt"), options, 7);
  EXPECT_EQ(start.options.run_id, "ramp-d7");
  EXPECT_EQ(start.state.agents.size(), start.scenario.slots.size());
}

TEST(CheckWithoutBus, AnAgentCountBeyondTheSlotsIsRefusedWithExit2) {
  RuntimeOptions options;
  options.out_dir.clear();
  options.agents = 1000;
  std::ostringstream out, err;
  EXPECT_EQ(run_scenario_check(shipped("ramp.pbtxt"), options, 0, false, out, err), kExitInvalidScenario);
  EXPECT_NE(err.str().find("exceeds the"), std::string::npos) << err.str();
}

}  // namespace
}  // namespace marsala::world_server
