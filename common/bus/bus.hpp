#pragma once
// A small vendor-neutral publish/subscribe interface. Backends: Cyclone DDS, Fast DDS (both compiled in,
// chosen at run time) and an in-process one for tests. One topic per message type; partitions separate
// agents; every endpoint is RELIABLE.
//
//   auto participant = bus::make_participant({bus::Vendor::kCyclone, domain_id});
//   auto signal = std::make_shared<bus::Signal>();
//   auto frames = participant->create_reader<bus::SensorFrame>({bus::partition_for(run, id), signal});
//   while (signal->wait_for(100ms)) for (auto& f : frames->take()) ...
//
// Threads: backends deliver on their own threads; readers queue samples and notify the endpoint's Signal.
// Nothing escapes a backend callback. take() and write() may be called from any thread.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "common/bus/messages.hpp"

namespace marsala::bus {

/// The DDS implementation behind a participant.
enum class Vendor { kCyclone, kFastDds, kInProcess };
std::string to_string(Vendor v);
/// "cyclone", "fastdds" or "inprocess"; anything else throws InvalidArgument listing the valid names.
Vendor vendor_from_string(const std::string& name);

/// A wake-up shared by endpoints and the thread that waits on them (data arrived, a writer came or went).
class Signal {
 public:
  /// Wakes the waiter; callable from any thread.
  void notify();
  /// Waits until notified since the last wait or until `timeout`; true when notified.
  bool wait_for(std::chrono::nanoseconds timeout);
  /// Waits until notified or until `deadline`; true when notified.
  bool wait_until(std::chrono::steady_clock::time_point deadline);

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool pending_ = false;
};

/// Durability of a topic's samples for late joiners.
enum class Durability { kVolatile, kTransientLocal };

/// Options of one reader or writer.
struct EndpointOptions {
  std::string partition;                 ///< empty = the default partition
  std::shared_ptr<Signal> signal;        ///< readers: notified on data and on writer liveliness changes
  Durability durability = Durability::kVolatile;
  std::int32_t depth = 64;               ///< KEEP_LAST history depth per instance
};

/// Writes samples of one message type.
template <typename T>
class Writer {
 public:
  virtual ~Writer() = default;
  /// Publishes one sample; throws bus::BusError when the backend fails.
  virtual void write(const T& sample) = 0;
  /// Readers currently matched [count].
  virtual int matched_readers() const = 0;
};

/// Receives samples of one message type.
template <typename T>
class Reader {
 public:
  virtual ~Reader() = default;
  /// Every sample received since the last take, in arrival order.
  virtual std::vector<T> take() = 0;
  /// Matched writers whose liveliness is currently asserted [count]; drops when a writer's process dies
  /// (after its liveliness lease, about 1 s).
  virtual int alive_writers() const = 0;
};

/// Tag type that selects a message type in the virtual interface below.
template <typename T>
struct Tag {};

/// A DDS domain participant (or its in-process stand-in): creates readers and writers.
class Participant {
 public:
  virtual ~Participant() = default;
  virtual Vendor vendor() const = 0;
  virtual int domain_id() const = 0;

  template <typename T>
  std::unique_ptr<Writer<T>> create_writer(const EndpointOptions& options = {}) {
    return make_writer(Tag<T>{}, options);
  }
  template <typename T>
  std::unique_ptr<Reader<T>> create_reader(const EndpointOptions& options = {}) {
    return make_reader(Tag<T>{}, options);
  }

 protected:
  virtual std::unique_ptr<Writer<AgentHello>> make_writer(Tag<AgentHello>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Writer<Admission>> make_writer(Tag<Admission>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Writer<SensorFrame>> make_writer(Tag<SensorFrame>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Writer<ActionRequest>> make_writer(Tag<ActionRequest>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Writer<WorldStatus>> make_writer(Tag<WorldStatus>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Writer<WorldEvent>> make_writer(Tag<WorldEvent>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Reader<AgentHello>> make_reader(Tag<AgentHello>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Reader<Admission>> make_reader(Tag<Admission>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Reader<SensorFrame>> make_reader(Tag<SensorFrame>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Reader<ActionRequest>> make_reader(Tag<ActionRequest>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Reader<WorldStatus>> make_reader(Tag<WorldStatus>, const EndpointOptions&) = 0;
  virtual std::unique_ptr<Reader<WorldEvent>> make_reader(Tag<WorldEvent>, const EndpointOptions&) = 0;
};

/// How to make a participant.
struct BusConfig {
  Vendor vendor = Vendor::kCyclone;
  int domain_id = 0;   ///< 0..232
};

/// Creates a participant of the chosen vendor; throws BusError naming vendor and domain on failure.
/// Loopback configuration comes from the environment (CYCLONEDDS_URI, FASTRTPS_DEFAULT_PROFILES_FILE);
/// deploy/ sets them for local runs.
std::unique_ptr<Participant> make_participant(const BusConfig& config);

}  // namespace marsala::bus
