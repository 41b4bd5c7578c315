#pragma once
// What both DDS backends must agree on to talk to each other: topic names per message type and the QoS
// constants of the wire contract (docs/runtime.md#topics). Type names come from idl/marsala.idl
// ("marsala::wire::<Type>") through each vendor's code generator.

#include <chrono>
#include <string>

#include <fmt/format.h>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"

namespace marsala::bus::detail {

/// The DDS topic that carries one message type (one topic per type).
template <typename T>
struct TopicName;
#define MARSALA_BUS_TOPIC(T)                            \
  template <>                                           \
  struct TopicName<T> {                                 \
    static constexpr const char* value = "marsala_" #T; \
  };
MARSALA_BUS_MESSAGES(MARSALA_BUS_TOPIC)
#undef MARSALA_BUS_TOPIC

// Durability on the wire. Every writer offers TRANSIENT_LOCAL and every Cyclone reader requests it; a reader the
// caller asked to be volatile then drops samples written before it was created (source timestamp, see
// VolatileFilter). Why: a volatile Cyclone reader starts a non-Cyclone writer's stream at the first heartbeat it
// sees, so a Fast DDS writer's samples written while the Cyclone side is still connecting (the writer already
// matched) are lost for good; as transient-local it asks for them again. A volatile Cyclone writer cannot serve a
// transient-local reader, hence transient-local writers everywhere (Cyclone keeps 1 sample for late joiners then).

/// AUTOMATIC liveliness lease of every writer: a reader sees a dead writer's process as not alive after this.
inline constexpr std::chrono::milliseconds kWriterLease{1000};
/// Lease by which Fast DDS readers judge a writer (>= kWriterLease for QoS compatibility). Longer than the writer
/// lease because Cyclone asserts automatic liveliness only every 0.8 lease; Cyclone readers use the writer's lease.
inline constexpr std::chrono::milliseconds kReaderLease{1500};
/// How often a Fast DDS participant asserts its automatic writers (Cyclone derives it: 80 % of the lease).
inline constexpr std::chrono::milliseconds kLivelinessAnnouncement{250};
/// How long a reliable write may block when the writer's resend buffer is full.
inline constexpr std::chrono::milliseconds kMaxBlocking{1000};

/// Throws InvalidArgument for options no backend can honour (depth < 1).
inline void check_options(const EndpointOptions& options) {
  if (options.depth < 1) throw InvalidArgument(fmt::format("bus endpoint depth must be >= 1, got {}", options.depth));
}

}  // namespace marsala::bus::detail
