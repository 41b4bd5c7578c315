#include "marsala/bus/fastdds/fastdds_decode_filter.hpp"

#include <fastdds/dds/topic/TopicDataType.hpp>
#include <spdlog/spdlog.h>

#include <mutex>
#include <string>

#include "marsala/bus/detail/sample_conversion.hpp"

namespace marsala::bus::fastdds {
namespace {

namespace dds = eprosima::fastdds::dds;

// Fast DDS's interfaces have no virtual destructor; instances are deleted as DecodeFilter only (below).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
/// Passes a sample when `type_` decodes its payload; counts and logs (1st, 10th, 100th ...) the others.
class DecodeFilter final : public dds::IContentFilter {
 public:
  // The type support's methods are not const, but creating, reading into and deleting a sample changes nothing in it.
  explicit DecodeFilter(const dds::TopicDataType* type) : type_(const_cast<dds::TopicDataType*>(type)) {}

  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo&, const GUID_t&) const override {
    void* sample = type_->createData();
    bool decodes = false;
    try {
      // deserialize() only reads the payload; it takes a non-const pointer for the buffer it wraps.
      decodes = type_->deserialize(const_cast<SerializedPayload*>(&payload), sample);
    } catch (...) {
      decodes = false;
    }
    type_->deleteData(sample);
    if (!decodes) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (dropped_.count())
        spdlog::warn("bus (fastdds): dropped a sample of {} that does not decode as it ({} so far): a foreign type "
                     "under its name",
                     type_->getName(), dropped_.total());
    }
    return decodes;
  }

 private:
  dds::TopicDataType* type_;
  mutable std::mutex mutex_;                 // evaluate() runs on every receive thread of the participant
  mutable detail::MalformedSamples dropped_;
};
#pragma GCC diagnostic pop

}  // namespace

DecodeFilterFactory::ReturnCode_t DecodeFilterFactory::create_content_filter(
    const char*, const char*, const dds::TopicDataType* data_type, const char*, const ParameterSeq&,
    dds::IContentFilter*& filter_instance) {
  if (data_type == nullptr) return ReturnCode_t::RETCODE_BAD_PARAMETER;
  // nullptr when created; an update (new expression or parameters) keeps the instance: it uses neither
  if (filter_instance == nullptr) filter_instance = new DecodeFilter(data_type);
  return ReturnCode_t::RETCODE_OK;
}

DecodeFilterFactory::ReturnCode_t DecodeFilterFactory::delete_content_filter(const char*,
                                                                             dds::IContentFilter* filter_instance) {
  delete static_cast<DecodeFilter*>(filter_instance);  // IContentFilter has no virtual destructor
  return ReturnCode_t::RETCODE_OK;
}

}  // namespace marsala::bus::fastdds
