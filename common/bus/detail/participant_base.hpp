#pragma once
// The one place that maps Participant's per-type virtual interface onto a backend's two templates:
//   class MyParticipant final : public ParticipantBase<MyParticipant> { ...
//     template <typename T> std::unique_ptr<Writer<T>> writer(const EndpointOptions&);
//     template <typename T> std::unique_ptr<Reader<T>> reader(const EndpointOptions&); };

#include <memory>

#include "common/bus/bus.hpp"

namespace marsala::bus::detail {

template <typename Backend>
class ParticipantBase : public Participant {
 protected:
  // clang-format off
  std::unique_ptr<Writer<AgentHello>> make_writer(Tag<AgentHello>, const EndpointOptions& o) override { return self().template writer<AgentHello>(o); }
  std::unique_ptr<Writer<Admission>> make_writer(Tag<Admission>, const EndpointOptions& o) override { return self().template writer<Admission>(o); }
  std::unique_ptr<Writer<SensorFrame>> make_writer(Tag<SensorFrame>, const EndpointOptions& o) override { return self().template writer<SensorFrame>(o); }
  std::unique_ptr<Writer<ActionRequest>> make_writer(Tag<ActionRequest>, const EndpointOptions& o) override { return self().template writer<ActionRequest>(o); }
  std::unique_ptr<Writer<WorldStatus>> make_writer(Tag<WorldStatus>, const EndpointOptions& o) override { return self().template writer<WorldStatus>(o); }
  std::unique_ptr<Writer<WorldEvent>> make_writer(Tag<WorldEvent>, const EndpointOptions& o) override { return self().template writer<WorldEvent>(o); }
  std::unique_ptr<Reader<AgentHello>> make_reader(Tag<AgentHello>, const EndpointOptions& o) override { return self().template reader<AgentHello>(o); }
  std::unique_ptr<Reader<Admission>> make_reader(Tag<Admission>, const EndpointOptions& o) override { return self().template reader<Admission>(o); }
  std::unique_ptr<Reader<SensorFrame>> make_reader(Tag<SensorFrame>, const EndpointOptions& o) override { return self().template reader<SensorFrame>(o); }
  std::unique_ptr<Reader<ActionRequest>> make_reader(Tag<ActionRequest>, const EndpointOptions& o) override { return self().template reader<ActionRequest>(o); }
  std::unique_ptr<Reader<WorldStatus>> make_reader(Tag<WorldStatus>, const EndpointOptions& o) override { return self().template reader<WorldStatus>(o); }
  std::unique_ptr<Reader<WorldEvent>> make_reader(Tag<WorldEvent>, const EndpointOptions& o) override { return self().template reader<WorldEvent>(o); }
  // clang-format on

 private:
  Backend& self() { return static_cast<Backend&>(*this); }
};

}  // namespace marsala::bus::detail
