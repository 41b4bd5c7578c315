#pragma once
// A Fast DDS content filter that keeps only samples the topic's type decodes (docs/runtime.md#foreign-types): a
// foreign type's samples under a MARSala type's name are dropped as they arrive, before they take a place in the
// reader's history, so a flood of them cannot push genuine samples out.

#include <fastdds/dds/topic/IContentFilterFactory.hpp>

namespace marsala::bus::fastdds {

/// The filter class name readers' content-filtered topics use (registered on every participant of the bus).
inline constexpr const char* kDecodeFilterClass = "MARSALA_DECODES";
/// The filter expression of those topics: unused by the filter, but Fast DDS filters nothing under an empty one.
inline constexpr const char* kDecodeFilterExpression = "decodes";

// Fast DDS's interface has no virtual destructor; the bus keeps one factory for the process and never deletes it.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
/// Makes one decode filter per content-filtered topic; stateless, so one factory serves every participant.
class DecodeFilterFactory final : public eprosima::fastdds::dds::IContentFilterFactory {
 public:
  /// A filter that decodes each sample with `data_type` (the topic's type support); RETCODE_BAD_PARAMETER without one.
  ReturnCode_t create_content_filter(const char* filter_class_name, const char* type_name,
                                     const eprosima::fastdds::dds::TopicDataType* data_type,
                                     const char* filter_expression, const ParameterSeq& filter_parameters,
                                     eprosima::fastdds::dds::IContentFilter*& filter_instance) override;
  /// Deletes a filter this factory made.
  ReturnCode_t delete_content_filter(const char* filter_class_name,
                                     eprosima::fastdds::dds::IContentFilter* filter_instance) override;
};
#pragma GCC diagnostic pop

}  // namespace marsala::bus::fastdds
