#include "marsala/bus/fastdds/fastdds_timing.hpp"

#include <fastdds/rtps/attributes/ReaderAttributes.h>
#include <fastdds/rtps/attributes/WriterAttributes.h>
#include <fastrtps/attributes/PublisherAttributes.h>
#include <fastrtps/attributes/SubscriberAttributes.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala::bus::fastdds {
namespace {

using eprosima::fastrtps::Duration_t;

long long nanoseconds(const Duration_t& d) { return static_cast<long long>(d.seconds) * 1000000000LL + d.nanosec; }

}  // namespace

void fast_repair(eprosima::fastrtps::rtps::WriterTimes& times) {
  if (times.heartbeatPeriod != eprosima::fastrtps::rtps::WriterTimes().heartbeatPeriod) return;
  times.heartbeatPeriod = Duration_t(0, static_cast<std::uint32_t>(
                                            std::chrono::duration_cast<std::chrono::nanoseconds>(kRepairHeartbeat).count()));
  times.nackResponseDelay = Duration_t(0, 0);
}

void fast_repair(eprosima::fastrtps::rtps::ReaderTimes& times) {
  if (times.heartbeatResponseDelay != eprosima::fastrtps::rtps::ReaderTimes().heartbeatResponseDelay) return;
  times.heartbeatResponseDelay = Duration_t(0, 0);
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
  return {nanoseconds(writer.times.heartbeatPeriod), nanoseconds(writer.times.nackResponseDelay),
          nanoseconds(reader.times.heartbeatResponseDelay),
          writer.times == writer_profile && reader.times == reader_profile};
}

}  // namespace marsala::bus::fastdds
