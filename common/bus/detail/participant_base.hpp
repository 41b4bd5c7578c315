#pragma once
// The one place that maps Participant's per-type virtual interface onto a backend's two templates:
//   class MyParticipant final : public ParticipantBase<MyParticipant> { ...
//     template <typename T> std::unique_ptr<Writer<T>> writer(const EndpointOptions&);
//     template <typename T> std::unique_ptr<Reader<T>> reader(const EndpointOptions&); };

#include <memory>

#include "marsala/bus/bus.hpp"

namespace marsala::bus::detail {

template <typename Backend>
class ParticipantBase : public Participant {
 protected:
#define MARSALA_BUS_ENDPOINTS(T)                                                      \
  std::unique_ptr<Writer<T>> make_writer(Tag<T>, const EndpointOptions& o) override { \
    return self().template writer<T>(o);                                              \
  }                                                                                   \
  std::unique_ptr<Reader<T>> make_reader(Tag<T>, const EndpointOptions& o) override { \
    return self().template reader<T>(o);                                              \
  }
  MARSALA_BUS_MESSAGES(MARSALA_BUS_ENDPOINTS)
#undef MARSALA_BUS_ENDPOINTS

 private:
  Backend& self() { return static_cast<Backend&>(*this); }
};

}  // namespace marsala::bus::detail
