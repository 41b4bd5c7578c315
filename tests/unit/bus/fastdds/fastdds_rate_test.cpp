#include "marsala/bus/fastdds/fastdds_rate.hpp"

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/rtps/attributes/PropertyPolicy.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::bus::fastdds {
namespace {

using eprosima::fastrtps::rtps::PropertyPolicy;

PropertyPolicy properties(std::initializer_list<std::pair<const char*, const char*>> pairs) {
  PropertyPolicy policy;
  for (const auto& [name, value] : pairs) policy.properties().emplace_back(name, value);
  return policy;
}

TEST(FastDdsRateTest, NoBytesPropertyMeansNoLimitAndThePeriodDefaultsToAHundredMilliseconds) {
  EXPECT_FALSE(rate_limit_of(properties({})));
  EXPECT_FALSE(rate_limit_of(properties({{kRatePeriodProperty, "40"}})));
  const std::optional<RateLimit> limit = rate_limit_of(properties({{kRateBytesProperty, "4000"}}));
  ASSERT_TRUE(limit);
  EXPECT_EQ(limit->bytes_per_period, 4000);
  EXPECT_EQ(limit->period_ms, 100u);
}

TEST(FastDdsRateTest, AValueThatIsNotAPositiveIntegerIsAnErrorNamingTheProperty) {
  for (const char* bad : {"", "abc", "12kB", "-5", "1499", "99999999999"}) {
    try {
      rate_limit_of(properties({{kRateBytesProperty, bad}}));
      FAIL() << "no throw for '" << bad << "'";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find(kRateBytesProperty), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(rate_limit_of(properties({{kRateBytesProperty, "4000"}, {kRatePeriodProperty, "0"}})), InvalidArgument);
}

TEST(FastDdsRateTest, ALimitRegistersOneNamedControllerThatWritersPublishThroughAsynchronously) {
  eprosima::fastdds::dds::DomainParticipantQos participant;
  limit_rate(participant, RateLimit{2500, 20});
  ASSERT_EQ(participant.flow_controllers().size(), 1u);
  EXPECT_STREQ(participant.flow_controllers()[0]->name, kRateController);
  EXPECT_EQ(participant.flow_controllers()[0]->max_bytes_per_period, 2500);
  EXPECT_EQ(participant.flow_controllers()[0]->period_ms, 20u);

  eprosima::fastdds::dds::DataWriterQos writer;
  EXPECT_EQ(writer.publish_mode().kind, eprosima::fastdds::dds::SYNCHRONOUS_PUBLISH_MODE);
  publish_through_rate(writer);
  EXPECT_EQ(writer.publish_mode().kind, eprosima::fastdds::dds::ASYNCHRONOUS_PUBLISH_MODE);
  EXPECT_STREQ(writer.publish_mode().flow_controller_name, kRateController);
}

// The shipped slow-link profile (docs/runtime.md#slow-links) stays under a 1 Mbit/s link: at most 125,000 bytes a
// second from one process.
TEST(FastDdsRateTest, TheSlowLinkProfileLimitsAProcessBelowOneMegabitPerSecond) {
  const char* root = std::getenv("MARSALA_SOURCE_DIR");
  const std::string path = (std::filesystem::path(root ? root : ".") / "deploy/dds/fastdds-slow.xml").string();
  using eprosima::fastrtps::xmlparser::XMLProfileManager;
  ASSERT_EQ(XMLProfileManager::loadXMLFile(path), eprosima::fastrtps::xmlparser::XMLP_ret::XML_OK) << path;
  eprosima::fastrtps::ParticipantAttributes attributes;
  ASSERT_EQ(XMLProfileManager::fillParticipantAttributes("slow_loopback", attributes),
            eprosima::fastrtps::xmlparser::XMLP_ret::XML_OK);
  const std::optional<RateLimit> limit = rate_limit_of(attributes.rtps.properties);
  ASSERT_TRUE(limit);
  EXPECT_LE(static_cast<double>(limit->bytes_per_period) * 1000.0 / static_cast<double>(limit->period_ms), 125000.0);
}

}  // namespace
}  // namespace marsala::bus::fastdds
