#include "marsala/bus/fastdds/fastdds_timing.hpp"

#include <fastdds/rtps/attributes/ReaderAttributes.h>
#include <fastdds/rtps/attributes/WriterAttributes.h>
#include <fastrtps/attributes/PublisherAttributes.h>
#include <fastrtps/attributes/SubscriberAttributes.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

#include "marsala/core/error.hpp"

namespace marsala::bus::fastdds {
namespace {

using eprosima::fastrtps::Duration_t;

long long nanoseconds(const Duration_t& d) { return static_cast<long long>(d.seconds) * 1000000000LL + d.nanosec; }
Duration_t duration_of(long long ns) {
  return Duration_t(static_cast<std::int32_t>(ns / 1000000000LL), static_cast<std::uint32_t>(ns % 1000000000LL));
}

}  // namespace

void fast_repair(eprosima::fastrtps::rtps::WriterTimes& times) {
  if (times.heartbeatPeriod != eprosima::fastrtps::rtps::WriterTimes().heartbeatPeriod) return;
  times.heartbeatPeriod = duration_of(std::chrono::duration_cast<std::chrono::nanoseconds>(kRepairHeartbeat).count());
  times.nackResponseDelay = Duration_t(0, 0);
}

void fast_repair(eprosima::fastrtps::rtps::ReaderTimes& times) {
  if (times.heartbeatResponseDelay != eprosima::fastrtps::rtps::ReaderTimes().heartbeatResponseDelay) return;
  times.heartbeatResponseDelay = Duration_t(0, 0);
}

long long team_heartbeat_ns(long long period_ns, bool serves_team) {
  if (serves_team) return period_ns;
  const long long shortest = std::chrono::duration_cast<std::chrono::nanoseconds>(kShortestHeartbeat).count();
  return std::min(period_ns, std::max(shortest, period_ns / kOneReaderHeartbeatDivisor));
}

void follow_team(eprosima::fastrtps::rtps::WriterTimes& times, bool serves_team) {
  const long long ns = team_heartbeat_ns(nanoseconds(times.heartbeatPeriod), serves_team);
  times.heartbeatPeriod = duration_of(ns);
}

RepairTiming repair_timing_of_profile(const std::string& path) {
  using eprosima::fastrtps::xmlparser::XMLP_ret;
  using eprosima::fastrtps::xmlparser::XMLProfileManager;
  if (XMLProfileManager::loadXMLFile(path) != XMLP_ret::XML_OK)
    throw InvalidArgument(fmt::format("Fast DDS cannot load the profile file {}", path));
  eprosima::fastrtps::PublisherAttributes writer;
  eprosima::fastrtps::SubscriberAttributes reader;
  XMLProfileManager::getDefaultPublisherAttributes(writer);
  XMLProfileManager::getDefaultSubscriberAttributes(reader);
  const eprosima::fastrtps::rtps::WriterTimes writer_profile = writer.times;
  const eprosima::fastrtps::rtps::ReaderTimes reader_profile = reader.times;
  fast_repair(writer.times);
  fast_repair(reader.times);
  const long long period = nanoseconds(writer.times.heartbeatPeriod);
  return {period, team_heartbeat_ns(period, false), nanoseconds(writer.times.nackResponseDelay),
          nanoseconds(reader.times.heartbeatResponseDelay),
          writer.times == writer_profile && reader.times == reader_profile};
}

}  // namespace marsala::bus::fastdds
