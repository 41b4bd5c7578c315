// marsala-foreign-type: a Fast DDS writer of a foreign type under a MARSala type's name, for integration tests
// (issue 30, docs/runtime.md#foreign-types). It registers the 12-byte ScanPoint layout as "marsala::wire::<TYPE>"
// and floods topic marsala_<TYPE> on a partition (wildcards allowed) with it: every reader of TYPE there matches it
// and gets samples it cannot read. Those must cost the reader bounded log and never its genuine samples.
//
// Usage: marsala-foreign-type DOMAIN TYPE PARTITION SECONDS
//   e.g. marsala-foreign-type 7 ActionRequest 'ramp-d7/agent-1-*' 5. Prints "matched" once a reader matched (then
//   floods for SECONDS) and how many samples it wrote; exits 0, 1 when no reader matched within 20 s, 2 on bad
//   arguments or when DDS refuses the endpoint.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <chrono>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>

#include "marsalaPubSubTypes.h"

namespace {

namespace dds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

/// The ScanPoint layout under another type's name.
class ForeignPubSubType : public marsala::wire::ScanPointPubSubType {
 public:
  explicit ForeignPubSubType(const std::string& name) { setName(name.c_str()); }
};

int run(int argc, char** argv) {
  if (argc != 5) throw std::invalid_argument("usage: marsala-foreign-type DOMAIN TYPE PARTITION SECONDS");
  const int domain = std::stoi(argv[1]);
  const std::string type_name = std::string("marsala::wire::") + argv[2];
  const std::string topic_name = std::string("marsala_") + argv[2];
  const auto seconds = std::chrono::duration<double>(std::stod(argv[4]));
  dds::DomainParticipant* participant =
      dds::DomainParticipantFactory::get_instance()->create_participant(domain, dds::PARTICIPANT_QOS_DEFAULT);
  if (participant == nullptr) throw std::runtime_error("no participant");
  dds::TypeSupport type(new ForeignPubSubType(type_name));
  type.register_type(participant);
  dds::Topic* topic = participant->create_topic(topic_name, type_name, dds::TOPIC_QOS_DEFAULT);
  dds::PublisherQos pub_qos = participant->get_default_publisher_qos();
  pub_qos.partition().push_back(argv[3]);
  dds::Publisher* publisher = participant->create_publisher(pub_qos);
  dds::DataWriterQos qos = publisher ? publisher->get_default_datawriter_qos() : dds::DataWriterQos();
  // What MARSala's readers ask for (common/bus/detail/topics.hpp): reliable, a lease of at most 1 s.
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = 64;
  qos.liveliness().kind = dds::AUTOMATIC_LIVELINESS_QOS;
  qos.liveliness().lease_duration = eprosima::fastrtps::Duration_t(1, 0);
  qos.liveliness().announcement_period = eprosima::fastrtps::Duration_t(0, 250000000);
  dds::DataWriter* writer = topic && publisher ? publisher->create_datawriter(topic, qos) : nullptr;
  if (writer == nullptr) throw std::runtime_error("no writer for " + topic_name);
  dds::PublicationMatchedStatus matched;
  for (auto deadline = Clock::now() + std::chrono::seconds(20); Clock::now() < deadline;) {
    writer->get_publication_matched_status(matched);
    if (matched.current_count > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (matched.current_count == 0) {
    std::cout << "unmatched" << std::endl;
    return 1;
  }
  std::cout << "matched" << std::endl;
  marsala::wire::ScanPoint sample;
  std::uint64_t written = 0;
  for (const auto end = Clock::now() + seconds; Clock::now() < end;) {
    sample.x_m(static_cast<float>(written));
    if (writer->write(&sample)) ++written;
  }
  std::cout << "wrote " << written << " samples of a foreign " << type_name << " on " << topic_name << " to "
            << matched.current_count << " matched readers" << std::endl;
  participant->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "marsala-foreign-type: " << e.what() << "\n";
    return 2;
  }
}
