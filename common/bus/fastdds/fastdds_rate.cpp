#include "marsala/bus/fastdds/fastdds_rate.hpp"

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/rtps/attributes/PropertyPolicy.h>
#include <fastdds/rtps/flowcontrol/FlowControllerDescriptor.hpp>
#include <fmt/format.h>
#include <tinyxml2.h>

#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala::bus::fastdds {
namespace {

/// The property `name` of `properties` as an integer in [least, most], none when absent.
std::optional<long long> integer_property(const eprosima::fastrtps::rtps::PropertyPolicy& properties,
                                          const char* name, long long least, long long most) {
  const std::string* text = eprosima::fastrtps::rtps::PropertyPolicyHelper::find_property(properties, name);
  if (text == nullptr) return std::nullopt;
  char* end = nullptr;
  const long long value = std::strtoll(text->c_str(), &end, 10);
  if (text->empty() || *end != '\0' || value < least || value > most)
    throw InvalidArgument(fmt::format("Fast DDS profile property {} must be an integer from {} to {}, got '{}'", name,
                                      least, most, *text));
  return value;
}

}  // namespace

std::optional<RateLimit> rate_limit_of(const eprosima::fastrtps::rtps::PropertyPolicy& properties) {
  const std::optional<long long> bytes =
      integer_property(properties, kRateBytesProperty, 1500, std::numeric_limits<std::int32_t>::max());
  const std::optional<long long> period = integer_property(properties, kRatePeriodProperty, 1, 60'000);
  if (!bytes) return std::nullopt;
  return RateLimit{static_cast<std::int32_t>(*bytes), static_cast<std::uint64_t>(period.value_or(100))};
}

std::optional<RateLimit> rate_limit_of_profile(const std::string& path) {
  // Read with tinyxml2 (Fast DDS's own XML library) rather than Fast DDS's profile manager, which keeps every file it
  // loads for the process and refuses a second file with the same profile names.
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS)
    throw InvalidArgument(fmt::format("DDS profile '{}' is not an XML document: {}", path, doc.ErrorStr()));
  // Every participant profile's properties: a bad rate limit is refused wherever it is written.
  std::optional<RateLimit> limit;
  std::vector<const tinyxml2::XMLElement*> pending{doc.RootElement()};
  while (!pending.empty()) {
    const tinyxml2::XMLElement* element = pending.back();
    pending.pop_back();
    if (element == nullptr) continue;
    if (std::string(element->Name()) == "participant") {
      eprosima::fastrtps::rtps::PropertyPolicy properties;
      const tinyxml2::XMLElement* list = element->FirstChildElement("rtps");
      list = list ? list->FirstChildElement("propertiesPolicy") : nullptr;
      list = list ? list->FirstChildElement("properties") : nullptr;
      for (const tinyxml2::XMLElement* p = list ? list->FirstChildElement("property") : nullptr; p != nullptr;
           p = p->NextSiblingElement("property")) {
        const tinyxml2::XMLElement* name = p->FirstChildElement("name");
        const tinyxml2::XMLElement* value = p->FirstChildElement("value");
        if (name != nullptr && name->GetText() != nullptr)
          properties.properties().emplace_back(name->GetText(),
                                               value != nullptr && value->GetText() != nullptr ? value->GetText() : "");
      }
      try {
        if (const std::optional<RateLimit> found = rate_limit_of(properties)) limit = found;
      } catch (const InvalidArgument& e) {
        throw InvalidArgument(fmt::format("DDS profile '{}': {}", path, e.what()));
      }
      continue;
    }
    for (const tinyxml2::XMLElement* child = element->FirstChildElement(); child != nullptr;
         child = child->NextSiblingElement())
      pending.push_back(child);
  }
  return limit;
}

void limit_rate(eprosima::fastdds::dds::DomainParticipantQos& qos, const RateLimit& limit) {
  auto controller = std::make_shared<eprosima::fastdds::rtps::FlowControllerDescriptor>();
  controller->name = kRateController;  // a literal: outlives every participant
  controller->max_bytes_per_period = limit.bytes_per_period;
  controller->period_ms = limit.period_ms;
  qos.flow_controllers().push_back(controller);
}

void publish_through_rate(eprosima::fastdds::dds::DataWriterQos& qos) {
  qos.publish_mode().kind = eprosima::fastdds::dds::ASYNCHRONOUS_PUBLISH_MODE;
  qos.publish_mode().flow_controller_name = kRateController;
}

}  // namespace marsala::bus::fastdds
