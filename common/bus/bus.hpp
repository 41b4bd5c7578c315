#pragma once
// A small vendor-neutral publish/subscribe interface. Backends: Cyclone DDS, Fast DDS (both compiled in,
// chosen at run time) and an in-process one for tests. One topic per message type; partitions separate
// agents; every endpoint is RELIABLE.
//
//   auto participant = bus::make_participant({bus::Vendor::kCyclone, domain_id});
//   auto signal = std::make_shared<bus::Signal>();
//   auto frames = participant->create_reader<protocol::SensorFrame>({protocol::partition_for(run, id), signal});
//   while (signal->wait_for(100ms)) for (auto& f : frames->take()) ...
//
// Threads: backends deliver on their own threads; readers queue samples and notify the endpoint's Signal, or call its
// on_data handler on the backend's thread instead (the sample is then taken without waking another thread). Nothing
// escapes a backend callback. take() and write() may be called from any thread.

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "marsala/protocol/messages.hpp"

/// The message types the bus carries, in one place: X(Type) once for each protocol message that has its own topic.
/// Participant's interface, each backend's endpoints and the topic names ("marsala_<Type>") are all made from it,
/// so adding a message means adding it here, to idl/marsala.idl and to each backend's converter.
#define MARSALA_BUS_MESSAGES(X) X(AgentHello) X(Admission) X(SensorFrame) X(ActionRequest) X(WorldStatus) X(WorldEvent)

namespace marsala::bus {

// The bus speaks of the protocol's messages by their own names.
#define MARSALA_BUS_USING(T) using protocol::T;
MARSALA_BUS_MESSAGES(MARSALA_BUS_USING)
#undef MARSALA_BUS_USING

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
  std::string partition;           ///< empty = the default partition
  std::shared_ptr<Signal> signal;  ///< readers: notified on data (unless on_data) and on writer liveliness changes
  Durability durability = Durability::kVolatile;
  std::int32_t depth = 64;  ///< KEEP_LAST history depth per instance
  /// Readers: when set, called on the backend's thread each time samples were queued, in place of notifying `signal`
  /// (which then wakes only on writer liveliness and match changes). It may take the samples and write on other
  /// endpoints, but not on a topic this process also reads (Cyclone delivers to local readers on the writing thread,
  /// and waits for their running callbacks); it must not throw, wait for long, nor destroy the reader.
  std::function<void()> on_data{};
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
  /// True when every matched reader has acknowledged every sample written so far (nothing left to deliver; also
  /// with no reader); a backend that cannot tell says true.
  virtual bool acknowledged() const { return true; }
};

/// The participant that wrote a sample: its RTPS GUID prefix, which every vendor sees alike (a Fast DDS reader and
/// a Cyclone reader name the same writer by the same 12 bytes). Through a DDS API a process cannot write under
/// another participant's prefix, so a receiver that pins the prefix of the world it was admitted to ignores what
/// anyone else sends in the world's name (docs/runtime.md#who-wrote-it). All zero: unknown.
struct WriterId {
  std::array<std::uint8_t, 12> prefix{};
  bool known() const {
    for (std::uint8_t b : prefix)
      if (b != 0) return true;
    return false;
  }
  friend bool operator==(const WriterId& a, const WriterId& b) { return a.prefix == b.prefix; }
  friend bool operator!=(const WriterId& a, const WriterId& b) { return !(a == b); }
  /// 24 hex digits, e.g. "0110d5a2c3e1f00100000000".
  std::string to_string() const;
};

/// A sample and the participant that wrote it.
template <typename T>
struct Received {
  T sample;
  WriterId from;
};

/// Receives samples of one message type.
template <typename T>
class Reader {
 public:
  virtual ~Reader() = default;
  /// Every sample received since the last take, in arrival order, with who wrote it.
  virtual std::vector<Received<T>> take_received() = 0;
  /// Every sample received since the last take, in arrival order.
  std::vector<T> take() {
    std::vector<Received<T>> received = take_received();
    std::vector<T> samples;
    samples.reserve(received.size());
    for (Received<T>& r : received) samples.push_back(std::move(r.sample));
    return samples;
  }
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
  /// How readers name this participant's samples (Received::from).
  virtual WriterId id() const = 0;

  template <typename T>
  std::unique_ptr<Writer<T>> create_writer(const EndpointOptions& options = {}) {
    return make_writer(Tag<T>{}, options);
  }
  template <typename T>
  std::unique_ptr<Reader<T>> create_reader(const EndpointOptions& options = {}) {
    return make_reader(Tag<T>{}, options);
  }

 protected:
#define MARSALA_BUS_ENDPOINTS(T)                                                      \
  virtual std::unique_ptr<Writer<T>> make_writer(Tag<T>, const EndpointOptions&) = 0; \
  virtual std::unique_ptr<Reader<T>> make_reader(Tag<T>, const EndpointOptions&) = 0;
  MARSALA_BUS_MESSAGES(MARSALA_BUS_ENDPOINTS)
#undef MARSALA_BUS_ENDPOINTS
};

/// Where a participant sits in the run's discovery star (docs/runtime.md#discovery-star). Agents talk only to the
/// world (and are watched by monitors), so an agent's participant need not know any other agent's: with every
/// participant discovering every other, a run of N agents pays N^2 discovery and liveliness messages (at 120
/// agents on 2 cores that alone saturated the machine and admission stalled at 44 of 120).
enum class Role {
  kServer,  ///< monitor, tools: takes the first free participant index from kServerIndices up, so that any number
            ///< of them leave indices 0..kServerIndices-1 to the world, and finds every participant on the domain
            ///< (the profile's whole unicast probe range and the world's ports)
  kClient,  ///< agent: finds only the participants at the world's ports and at indices 0..kServerIndices-1 and the
            ///< ones that find it; takes no port there (Cyclone: ParticipantIndex none; Fast DDS: ports from index
            ///< kServerIndices up)
  kWorld,   ///< the world: discovery on the first free of its own ports (world_discovery_port()), which no
            ///< participant with an automatic index can hold; finds every participant on the domain
};

/// Participant indices kept for the world: a client announces itself to these (and to the world's ports) only.
inline constexpr int kServerIndices = 4;

/// The world's own discovery ports of a domain [count]: world_discovery_port(domain, 0..kWorldPorts-1).
inline constexpr int kWorldPorts = 4;

/// The world's discovery (metatraffic unicast) port number `k` of `domain` [UDP port]: 7400 + 250 domain + 2 + 2 k,
/// k in 0..kWorldPorts-1, i.e. 7402, 7404, 7406, 7408 in domain 0. They lie between the domain's multicast ports
/// (offsets 0, 1) and participant index 0 (offset 10 + 2 i) of the RTPS port mapping, where no participant with an
/// automatic index of this domain ever binds (docs/runtime.md#discovery-star).
int world_discovery_port(int domain_id, int k);

/// DDS Security for a participant (docs/runtime.md#security): the folder deploy/security/make-identities.sh made
/// and the identity to take from it. Empty dir: unsecured.
struct Security {
  std::string dir;       ///< holds ca.pem, governance.p7s, permissions.p7s and <identity>.pem/.key
  std::string identity;  ///< file stem of the certificate and key: world, monitor, agent-<id>
  bool enabled() const { return !dir.empty(); }

  /// Security with `dir` (empty: off) and `identity`, or `fallback` when `identity` is empty.
  static Security of(const std::string& dir, const std::string& identity, const std::string& fallback) {
    if (dir.empty()) return {};
    return {dir, identity.empty() ? fallback : identity};
  }
};

/// The files of `security`, checked for a participant of `domain_id` (0..232): throws InvalidArgument naming the first
/// one missing, a private key open to other users, or a folder whose manifest names another domain.
void check_security(const Security& security, int domain_id);

/// How to make a participant.
struct BusConfig {
  BusConfig() = default;
  BusConfig(Vendor v, int domain, std::string profile_file = {}, Role r = Role::kServer, Security sec = {},
            std::vector<std::string> peer_hosts = {})
      : vendor(v),
        domain_id(domain),
        profile(std::move(profile_file)),
        role(r),
        security(std::move(sec)),
        peers(std::move(peer_hosts)) {}

  Vendor vendor = Vendor::kCyclone;
  int domain_id = 0;    ///< 0..232
  std::string profile;  ///< a profile file of the vendor; empty: resolve_profile()'s default
  Role role = Role::kServer;
  Security security;  ///< DDS Security; off when its dir is empty
  /// Hosts to discover by unicast, IPv4 addresses or names (--peers, docs/runtime.md#peers): multicast off, each probed
  /// at the world's ports and the profile's participant indices. Empty: discovery as the profile says.
  std::vector<std::string> peers;
};

/// The profile file a participant of `vendor` uses (docs/runtime.md#dds-profiles): `given` when not empty (it must
/// exist and be a profile of that vendor: a <CycloneDDS> or a Fast DDS <dds>/<profiles> document, else
/// InvalidArgument naming it); else empty when the vendor's own variable (CYCLONEDDS_URI,
/// FASTRTPS_DEFAULT_PROFILES_FILE) is set, which then applies; else the shipped loopback profile
/// (deploy/dds/<vendor>-lo.xml: share/marsala/dds beside the executable's folder, or the source tree it was built
/// from), so that processes started alone on one machine find each other, or with `unicast` (peers given) the
/// shipped unicast one (deploy/dds/<vendor>-unicast.xml: every interface, no multicast); empty when none is found.
/// Always empty for kInProcess.
std::string resolve_profile(Vendor vendor, const std::string& given, bool unicast = false);

/// What make_participant() would refuse in `config` before it makes anything: DDS Security's folder (check_security()),
/// the domain, the profile file (resolve_profile(); a Fast DDS one, given or the vendor's variable, also with valid
/// MARSala properties, docs/runtime.md#slow-links). Throws InvalidArgument naming the file, property or value, so a
/// program can refuse a bad configuration (exit 2) before it writes anything.
void check_config(const BusConfig& config);

/// Creates a participant of the chosen vendor with the profile resolve_profile() gives (set into the vendor's
/// variable before the vendor reads it); throws BusError naming vendor and domain on failure, InvalidArgument for a
/// bad domain or profile.
std::unique_ptr<Participant> make_participant(const BusConfig& config);

}  // namespace marsala::bus
