#include "marsala/bus/fastdds/fastdds_timing.hpp"

#include <fastdds/rtps/attributes/WriterAttributes.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::bus::fastdds {
namespace {

namespace fs = std::filesystem;

std::string source(const std::string& rel) {
  const char* root = std::getenv("MARSALA_SOURCE_DIR");
  return (fs::path(root ? root : ".") / rel).string();
}

/// The timing under a profile of text `text`, written to a file of this process in the temporary folder meanwhile.
RepairTiming timing_of(const std::string& name, const std::string& text) {
  const fs::path path = fs::temp_directory_path() / ("marsala_timing_" + std::to_string(::getpid()) + name + ".xml");
  std::ofstream(path) << text;
  const RepairTiming timing = repair_timing_of_profile(path.string());
  fs::remove(path);
  return timing;
}

// docs/runtime.md#lossy-links: a 50 ms heartbeat period for a writer serving the team, 5 ms for a writer serving one
// reader (an agent's, the world's in an agent's partition), repairs and answers to heartbeats at once [ns].
constexpr long long kShippedHeartbeatNs = 50'000'000;
constexpr long long kAgentHeartbeatNs = 5'000'000;

// Fast DDS keeps the default endpoint profile of the files it loaded in one process-wide store, so the cases run in
// this order in one test: a profile without endpoint timing first (Fast DDS's defaults underneath), then the shipped
// profiles, then one with timing of its own.
TEST(FastDdsTimingTest, ShippedProfilesAndTheFallbackRepairWithinFiftyMillisecondsAProfilesOwnTimingIsKept) {
  // like fastdds-unicast.xml (a template Fast DDS cannot load as it is): a participant profile only
  const RepairTiming bare = timing_of("bare", R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles>
  <participant profile_name="p" is_default_profile="true"><rtps><builtin><discovery_config>
    <leaseDuration><sec>10</sec></leaseDuration>
  </discovery_config></builtin></rtps></participant>
</profiles></dds>
)");
  EXPECT_EQ(bare.heartbeat_period_ns, kShippedHeartbeatNs);
  EXPECT_EQ(bare.one_reader_heartbeat_ns, kAgentHeartbeatNs);
  EXPECT_EQ(bare.nack_response_delay_ns, 0);
  EXPECT_EQ(bare.heartbeat_response_delay_ns, 0);
  EXPECT_FALSE(bare.from_profile);

  for (const char* shipped : {"deploy/dds/fastdds-lo.xml", "deploy/dds/fastdds-lan.xml"}) {
    const RepairTiming timing = repair_timing_of_profile(source(shipped));
    EXPECT_EQ(timing.heartbeat_period_ns, kShippedHeartbeatNs) << shipped;
    EXPECT_EQ(timing.one_reader_heartbeat_ns, kAgentHeartbeatNs) << shipped;
    EXPECT_EQ(timing.nack_response_delay_ns, 0) << shipped;
    EXPECT_EQ(timing.heartbeat_response_delay_ns, 0) << shipped;
    EXPECT_TRUE(timing.from_profile) << shipped << " leaves the timing to the bus";
  }
  // The crowd's profiles (48 agents or more, deploy/spawn.sh): ten times as slow.
  for (const char* crowd : {"deploy/dds/fastdds-crowd.xml", "deploy/dds/fastdds-unicast-crowd.xml"}) {
    const RepairTiming timing = repair_timing_of_profile(source(crowd));
    EXPECT_EQ(timing.heartbeat_period_ns, 10 * kShippedHeartbeatNs) << crowd;
    EXPECT_EQ(timing.one_reader_heartbeat_ns, 10 * kAgentHeartbeatNs) << crowd;
    EXPECT_EQ(timing.nack_response_delay_ns, 0) << crowd;
    EXPECT_EQ(timing.heartbeat_response_delay_ns, 0) << crowd;
    EXPECT_TRUE(timing.from_profile) << crowd << " leaves the timing to the bus";
  }

  const RepairTiming kept = timing_of("own", R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles>
  <data_writer profile_name="w" is_default_profile="true"><times>
    <heartbeatPeriod><sec>0</sec><nanosec>20000000</nanosec></heartbeatPeriod>
    <nackResponseDelay><sec>0</sec><nanosec>7000000</nanosec></nackResponseDelay>
  </times></data_writer>
  <data_reader profile_name="r" is_default_profile="true"><times>
    <heartbeatResponseDelay><sec>0</sec><nanosec>3000000</nanosec></heartbeatResponseDelay>
  </times></data_reader>
</profiles></dds>
)");
  EXPECT_EQ(kept.heartbeat_period_ns, 20'000'000);
  EXPECT_EQ(kept.one_reader_heartbeat_ns, 5'000'000);  // a tenth would be 2 ms: held at the 5 ms floor
  EXPECT_EQ(kept.nack_response_delay_ns, 7'000'000);
  EXPECT_EQ(kept.heartbeat_response_delay_ns, 3'000'000);
  EXPECT_TRUE(kept.from_profile);
}

// The rule (docs/runtime.md#lossy-links): a writer serving the team keeps its period; a writer serving one reader
// heartbeats ten times as often, never below 5 ms and never slower than the profile says.
TEST(FastDdsTimingTest, AOneReaderWriterHeartbeatsTenTimesAsOftenDownToFiveMilliseconds) {
  constexpr long long ms = 1'000'000;
  EXPECT_EQ(team_heartbeat_ns(50 * ms, true), 50 * ms);
  EXPECT_EQ(team_heartbeat_ns(50 * ms, false), 5 * ms);
  EXPECT_EQ(team_heartbeat_ns(200 * ms, false), 20 * ms);
  EXPECT_EQ(team_heartbeat_ns(3000 * ms, false), 300 * ms);
  EXPECT_EQ(team_heartbeat_ns(30 * ms, false), 5 * ms);
  EXPECT_EQ(team_heartbeat_ns(3 * ms, false), 3 * ms);  // a profile already faster than the floor is kept
  EXPECT_EQ(team_heartbeat_ns(3 * ms, true), 3 * ms);

  eprosima::fastrtps::rtps::WriterTimes times;
  times.heartbeatPeriod = eprosima::fastrtps::Duration_t(3, 0);
  follow_team(times, false);
  EXPECT_EQ(times.heartbeatPeriod, eprosima::fastrtps::Duration_t(0, 300'000'000));
  follow_team(times, true);
  EXPECT_EQ(times.heartbeatPeriod, eprosima::fastrtps::Duration_t(0, 300'000'000));
}

TEST(FastDdsTimingTest, AProfileFastDdsCannotLoadIsAnErrorNamingTheFile) {
  try {
    repair_timing_of_profile("/nonexistent/marsala-profile.xml");
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/marsala-profile.xml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace marsala::bus::fastdds
