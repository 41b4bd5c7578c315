#pragma once
// A rate limit for slow links (docs/runtime.md#slow-links): a participant profile that names one sends every sample
// through a Fast DDS flow controller, asynchronously, at most so many bytes per period.

#include <cstdint>
#include <optional>
#include <string>

namespace eprosima::fastrtps::rtps {
class PropertyPolicy;
}  // namespace eprosima::fastrtps::rtps
namespace eprosima::fastdds::dds {
class DomainParticipantQos;
class DataWriterQos;
}  // namespace eprosima::fastdds::dds

namespace marsala::bus::fastdds {

/// Participant property naming the bytes a participant's writers may send per period [bytes].
inline constexpr const char* kRateBytesProperty = "marsala.rate.bytes_per_period";
/// Participant property naming that period [ms].
inline constexpr const char* kRatePeriodProperty = "marsala.rate.period_ms";
/// Name of the flow controller a rate limit registers.
inline constexpr const char* kRateController = "marsala_rate";

/// At most `bytes_per_period` bytes of samples every `period_ms`.
struct RateLimit {
  std::int32_t bytes_per_period = 0;  ///< [bytes]
  std::uint64_t period_ms = 0;        ///< [ms]
};

/// The rate limit the participant properties `properties` name (kRateBytesProperty, kRatePeriodProperty; the period
/// defaults to 100 ms), none without kRateBytesProperty. Throws InvalidArgument naming the property when a value is
/// not a positive integer (bytes at least 1500: a datagram must fit in one period).
std::optional<RateLimit> rate_limit_of(const eprosima::fastrtps::rtps::PropertyPolicy& properties);

/// The rate limit a participant profile of the Fast DDS profile file `path` names (rate_limit_of() of its properties;
/// the last one found), none without one. Throws InvalidArgument naming the file when it is not XML or a value of any
/// participant profile is not valid, so that a bad profile is refused before anything runs.
std::optional<RateLimit> rate_limit_of_profile(const std::string& path);

/// Registers `limit` as the flow controller kRateController of participants made with `qos`.
void limit_rate(eprosima::fastdds::dds::DomainParticipantQos& qos, const RateLimit& limit);

/// Makes a writer publish asynchronously through kRateController.
void publish_through_rate(eprosima::fastdds::dds::DataWriterQos& qos);

}  // namespace marsala::bus::fastdds
