// The Cyclone DDS backend (C API). One participant per bus::Participant; one publisher or subscriber per
// endpoint, since the partition is a publisher/subscriber QoS; topics are created once per participant.
// Readers take samples on Cyclone's listener thread, convert them and queue them (detail::ReaderQueue).

#include <dds/dds.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "marsala/bus/cyclone/cyclone_convert.hpp"
#include "marsala/bus/cyclone/cyclone_log.hpp"
#include "marsala/bus/detail/backends.hpp"
#include "marsala/bus/detail/participant_base.hpp"
#include "marsala/bus/detail/reader_queue.hpp"
#include "marsala/bus/detail/sample_conversion.hpp"
#include "marsala/bus/detail/topics.hpp"
#include "marsala/core/error.hpp"

namespace marsala::bus::detail {
namespace {

/// The C type and topic descriptor idlc generated for a bus message.
template <typename T>
struct CycloneType;
template <>
struct CycloneType<AgentHello> {
  using Msg = marsala_wire_AgentHello;
  static const dds_topic_descriptor_t* descriptor() { return &marsala_wire_AgentHello_desc; }
};
template <>
struct CycloneType<Admission> {
  using Msg = marsala_wire_Admission;
  static const dds_topic_descriptor_t* descriptor() { return &marsala_wire_Admission_desc; }
};
template <>
struct CycloneType<SensorFrame> {
  using Msg = marsala_wire_SensorFrame;
  static const dds_topic_descriptor_t* descriptor() { return &marsala_wire_SensorFrame_desc; }
};
template <>
struct CycloneType<ActionRequest> {
  using Msg = marsala_wire_ActionRequest;
  static const dds_topic_descriptor_t* descriptor() { return &marsala_wire_ActionRequest_desc; }
};
template <>
struct CycloneType<WorldStatus> {
  using Msg = marsala_wire_WorldStatus;
  static const dds_topic_descriptor_t* descriptor() { return &marsala_wire_WorldStatus_desc; }
};
template <>
struct CycloneType<WorldEvent> {
  using Msg = marsala_wire_WorldEvent;
  static const dds_topic_descriptor_t* descriptor() { return &marsala_wire_WorldEvent_desc; }
};

/// How many participant indices a server tries from kServerIndices up before it becomes a client.
constexpr int kServerTries = 32;

/// Our Cyclone participants count participant indices from the world's first port (docs/runtime.md#discovery-star):
/// with the unicast offsets 2 (discovery) and 3 (data) instead of the RTPS mapping's 10 and 11, index j discovers on
/// 7402 + 250 d + 2 j, so indices 0..kWorldPorts-1 are the world's ports (bus::world_discovery_port()) and index
/// kWorldPorts + i is the mapping's index i. Every probe of "indices 0..n" thus reaches the world's ports first.
constexpr const char* kWorldFirstPorts =
    "<Discovery><Ports><UnicastMetaOffset>2</UnicastMetaOffset><UnicastDataOffset>3</UnicastDataOffset></Ports>"
    "</Discovery>";

std::string failure(const std::string& what, dds_return_t rc) {
  return fmt::format("Cyclone DDS: {} failed: {}", what, dds_strretcode(rc));
}

/// Owns a qos object for the duration of an endpoint's creation.
class Qos {
 public:
  Qos() : qos_(dds_create_qos()) {}
  ~Qos() { dds_delete_qos(qos_); }
  Qos(const Qos&) = delete;
  Qos& operator=(const Qos&) = delete;
  dds_qos_t* get() const { return qos_; }

 private:
  dds_qos_t* qos_;
};

/// The DDS participant and its topics; shared by the bus::Participant and every endpoint it made, so the
/// participant outlives its endpoints whatever order the caller destroys them in.
class Context {
 public:
  Context(int domain_id, Role role, const Security& security, const std::vector<std::string>& peers)
      : domain_id_(domain_id), peers_(peers_fragment(peers)) {
    cyclone::bound_cyclone_log();  // a foreign type's flood must not flood the log (cyclone_log.hpp)
    if (role == Role::kWorld) {
      if (open_at_first_free(security, 0, kWorldPorts + kServerIndices)) return;
      spdlog::warn("Cyclone DDS: the world's ports {} and up and participant indices 0..{} of domain {} are all taken "
                   "(by other worlds?): agents probe only those, so over unicast discovery they will not find this "
                   "world; run it on another domain (docs/runtime.md#discovery-star)",
                   world_discovery_port(domain_id, 0), kServerIndices - 1, domain_id);
    }
    if (role == Role::kServer && open_at_first_free(security, kWorldPorts + kServerIndices, kServerTries)) return;
    // The world as the profile says (an automatic index above the probed ones); a server with no free index of its
    // own as a client (an automatic index could take a world's port before the world starts).
    create_domain(role == Role::kWorld ? Role::kWorld : Role::kClient, security, -1);
    participant_ = dds_create_participant(static_cast<dds_domainid_t>(domain_id), nullptr, nullptr);
    if (participant_ < 0) {
      if (domain_ > 0) dds_delete(domain_);
      throw BusError(failure(fmt::format("creating a participant in domain {}", domain_id), participant_));
    }
  }
  ~Context() {
    dds_delete(participant_);
    if (domain_ > 0) dds_delete(domain_);
  }
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  dds_entity_t participant() const { return participant_; }
  int domain_id() const { return domain_id_; }

 private:
  /// The first free participant index of [first, first + count) (Cyclone has no "first free from N": each index is
  /// tried, quietly): the world within its ports and the indices agents probe (kWorldFirstPorts), so that no
  /// participant of another program, nor any number of monitors, keeps agents from finding it; a server (monitor,
  /// tool) above those, so that it never takes them (docs/runtime.md#discovery-star). False when all are taken (or
  /// the profile fails).
  bool open_at_first_free(const Security& security, int first, int count) {
    const std::uint32_t mask = dds_get_log_mask();
    dds_set_log_mask(DDS_LC_FATAL);  // a taken index is expected, not an error to print
    for (int index = first; index < first + count; ++index) {
      try {
        create_domain(Role::kServer, security, index);  // the world's settings are a server's
      } catch (const BusError&) {
        continue;
      }
      participant_ = dds_create_participant(static_cast<dds_domainid_t>(domain_id_), nullptr, nullptr);
      if (participant_ >= 0) break;
      if (domain_ > 0) dds_delete(domain_);
      domain_ = 0;
    }
    dds_set_log_mask(mask);
    return participant_ >= 0;
  }

  /// The domain with this participant's settings on top of the profile (CYCLONEDDS_URI), its indices counted from
  /// the world's first port (kWorldFirstPorts). A client: no participant index, so no other participant's unicast
  /// probes reach it; probes of its own only to the world's ports and the indices 0..kServerIndices-1 (Cyclone probes
  /// indices 0..MaxAutoParticipantIndex); its SPDP every second, so a world that restarts finds its agents within a
  /// second (they announce; the world cannot probe them). The world or a server: the index `fixed_index` (-1: the
  /// profile's). Secured: the three DDS Security plugins Debian ships with libddsc, with the identity's files.
  void create_domain(Role role, const Security& security, int fixed_index) {
    const char* uri = std::getenv("CYCLONEDDS_URI");
    std::string config = uri != nullptr && *uri != '\0' ? std::string(uri) : std::string();
    const auto add = [&config](const std::string& fragment) { config += (config.empty() ? "" : ",") + fragment; };
    add(kWorldFirstPorts);
    if (!peers_.empty()) add(peers_);
    if (role == Role::kClient)
      add(
          fmt::format("<Discovery><ParticipantIndex>none</ParticipantIndex><MaxAutoParticipantIndex>{}"
                      "</MaxAutoParticipantIndex><SPDPInterval>1s</SPDPInterval></Discovery>",
                      kWorldPorts + kServerIndices - 1));
    if (fixed_index >= 0)
      add(fmt::format("<Discovery><ParticipantIndex>{}</ParticipantIndex></Discovery>", fixed_index));
    if (security.enabled())
      add(fmt::format(
          R"(<Security><Authentication><Library path="dds_security_auth" initFunction="init_authentication" )"
          R"(finalizeFunction="finalize_authentication"/><IdentityCA>{0}ca.pem</IdentityCA>)"
          R"(<IdentityCertificate>{0}{1}.pem</IdentityCertificate><PrivateKey>{0}{1}.key</PrivateKey></Authentication>)"
          R"(<AccessControl><Library path="dds_security_ac" initFunction="init_access_control" )"
          R"(finalizeFunction="finalize_access_control"/><PermissionsCA>{0}ca.pem</PermissionsCA>)"
          R"(<Governance>{0}governance.p7s</Governance><Permissions>{0}permissions.p7s</Permissions></AccessControl>)"
          R"(<Cryptographic><Library path="dds_security_crypto" initFunction="init_crypto" )"
          R"(finalizeFunction="finalize_crypto"/></Cryptographic></Security>)",
          fmt::format("file:{}/", std::filesystem::absolute(security.dir).string()), security.identity));
    const dds_entity_t domain = dds_create_domain(static_cast<dds_domainid_t>(domain_id_), config.c_str());
    // Another participant of this process made the domain already: this one shares its configuration.
    if (domain == DDS_RETCODE_PRECONDITION_NOT_MET) return;
    if (domain < 0) throw BusError(failure(fmt::format("creating domain {} with its settings", domain_id_), domain));
    domain_ = domain;
  }

 public:
  /// The topic of message type T, created on first use.
  template <typename T>
  dds_entity_t topic() {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::string name = TopicName<T>::value;
    auto it = topics_.find(name);
    if (it != topics_.end()) return it->second;
    const dds_entity_t t = dds_create_topic(participant_, CycloneType<T>::descriptor(), name.c_str(), nullptr, nullptr);
    if (t < 0) throw BusError(failure(fmt::format("creating topic {}", name), t));
    topics_.emplace(name, t);
    return t;
  }

 private:
  /// Discovery by unicast at `peers` (IPv4 addresses, bus::resolve_peers()) and never by multicast, whatever the
  /// profile says (docs/runtime.md#peers); empty when there are none. Each peer is probed at the world's ports and the
  /// participant indices the role probes (kWorldFirstPorts).
  static std::string peers_fragment(const std::vector<std::string>& peers) {
    if (peers.empty()) return {};
    std::string listed;
    for (const std::string& peer : peers) listed += fmt::format(R"(<Peer address="{}"/>)", peer);
    return fmt::format("<General><AllowMulticast>false</AllowMulticast></General><Discovery><Peers>{}</Peers>"
                       "</Discovery>",
                       listed);
  }

  int domain_id_;
  std::string peers_;        ///< peers_fragment(): added to every domain this participant tries
  dds_entity_t domain_ = 0;  ///< a client's own domain entity; 0 when the participant uses the default one
  dds_entity_t participant_ = -1;
  std::mutex mutex_;
  std::map<std::string, dds_entity_t> topics_;
};

/// QoS shared by readers and writers: reliable, keep-last depth, transient-local on the wire (topics.hpp).
void set_common_qos(dds_qos_t* qos, const EndpointOptions& options) {
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(kMaxBlocking.count()));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, options.depth);
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
}

/// Publisher/subscriber QoS: the endpoint's partition ("" = the default partition: no partition QoS at all).
void set_partition(dds_qos_t* qos, const std::string& partition) {
  if (!partition.empty()) dds_qset_partition1(qos, partition.c_str());
}

template <typename T>
class CycloneWriter final : public Writer<T> {
 public:
  CycloneWriter(std::shared_ptr<Context> context, const EndpointOptions& options) : context_(std::move(context)) {
    check_options(options);
    const dds_entity_t topic = context_->template topic<T>();
    Qos pub_qos;
    set_partition(pub_qos.get(), options.partition);
    publisher_ = dds_create_publisher(context_->participant(), pub_qos.get(), nullptr);
    if (publisher_ < 0) throw BusError(failure(fmt::format("creating a publisher for {}", label(options)), publisher_));
    Qos qos;
    set_common_qos(qos.get(), options);
    // Late joiners get the last `depth` samples of a transient-local writer, and only the latest of a volatile one
    // (which its volatile readers drop).
    const std::int32_t kept = options.durability == Durability::kTransientLocal ? options.depth : 1;
    dds_qset_durability_service(qos.get(), 0, DDS_HISTORY_KEEP_LAST, kept, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED);
    dds_qset_liveliness(qos.get(), DDS_LIVELINESS_AUTOMATIC, DDS_MSECS(kWriterLease.count()));
    writer_ = dds_create_writer(publisher_, topic, qos.get(), nullptr);
    if (writer_ < 0) {
      dds_delete(publisher_);
      throw BusError(failure(fmt::format("creating a writer for {}", label(options)), writer_));
    }
  }
  // Deleting the publisher deletes its writer; Cyclone lingers briefly to deliver unacknowledged samples.
  ~CycloneWriter() override { dds_delete(publisher_); }

  void write(const T& sample) override {
    cyclone::Storage storage;
    const typename CycloneType<T>::Msg msg = cyclone::to_msg(sample, storage);
    const dds_return_t rc = dds_write(writer_, &msg);
    if (rc < 0) throw BusError(failure(fmt::format("writing {}", TopicName<T>::value), rc));
  }

  int matched_readers() const override {
    dds_publication_matched_status_t status{};
    if (dds_get_publication_matched_status(writer_, &status) < 0) return 0;
    return static_cast<int>(status.current_count);
  }

  bool acknowledged() const override { return dds_wait_for_acks(writer_, 0) == DDS_RETCODE_OK; }

 private:
  static std::string label(const EndpointOptions& options) {
    return fmt::format("{} in partition '{}'", TopicName<T>::value, options.partition);
  }

  std::shared_ptr<Context> context_;
  dds_entity_t publisher_ = 0;
  dds_entity_t writer_ = 0;
};

template <typename T>
class CycloneReader final : public Reader<T> {
 public:
  CycloneReader(std::shared_ptr<Context> context, const EndpointOptions& options)
      : context_(std::move(context)), filter_(options.durability), queue_(options.signal, options.on_data) {
    check_options(options);
    const dds_entity_t topic = context_->template topic<T>();
    Qos sub_qos;
    set_partition(sub_qos.get(), options.partition);
    subscriber_ = dds_create_subscriber(context_->participant(), sub_qos.get(), nullptr);
    if (subscriber_ < 0)
      throw BusError(failure(fmt::format("creating a subscriber for {}", TopicName<T>::value), subscriber_));
    Qos qos;
    set_common_qos(qos.get(), options);
    dds_listener_t* listener = dds_create_listener(this);
    dds_lset_data_available(listener, &CycloneReader::on_data_available);
    dds_lset_liveliness_changed(listener, &CycloneReader::on_liveliness_changed);
    dds_lset_subscription_matched(listener, &CycloneReader::on_subscription_matched);
    reader_ = dds_create_reader(subscriber_, topic, qos.get(), listener);
    dds_delete_listener(listener);
    if (reader_ < 0) {
      dds_delete(subscriber_);
      throw BusError(failure(fmt::format("creating a reader for {}", TopicName<T>::value), reader_));
    }
  }
  // Cyclone waits for a running listener callback to return before the reader is gone.
  ~CycloneReader() override { dds_delete(subscriber_); }

  std::vector<Received<T>> take_received() override { return queue_.take(); }

  int alive_writers() const override {
    dds_liveliness_changed_status_t status{};
    if (dds_get_liveliness_changed_status(reader_, &status) < 0) return 0;
    return static_cast<int>(status.alive_count);
  }

 private:
  static constexpr std::uint32_t kBatch = 16;

  /// Returns a loan of samples to the reader whatever happens while converting them.
  struct Loan {
    dds_entity_t reader;
    void** samples;
    std::int32_t count;
    ~Loan() {
      if (count > 0) dds_return_loan(reader, samples, count);
    }
  };

  /// The participant behind a matched writer: Cyclone names the writer of a sample by a local instance handle; its
  /// GUID comes from the matched publication's built-in data, asked once per writer.
  WriterId writer_of(dds_entity_t reader, dds_instance_handle_t handle) {
    const auto known = writers_.find(handle);
    if (known != writers_.end()) return known->second;
    WriterId id;
    if (dds_builtintopic_endpoint_t* endpoint = dds_get_matched_publication_data(reader, handle)) {
      std::copy_n(endpoint->key.v, id.prefix.size(), id.prefix.begin());  // a GUID = the prefix + an entity id
      dds_builtintopic_free_endpoint(endpoint);
      if (writers_.size() >= kMaxRememberedWriters) writers_.clear();
      writers_.emplace(handle, id);
    }
    return id;
  }

  void drain(dds_entity_t reader) {
    std::vector<Received<T>> received;
    for (;;) {
      void* samples[kBatch] = {};
      dds_sample_info_t infos[kBatch];
      const dds_return_t n = dds_take(reader, samples, infos, kBatch, kBatch);
      if (n <= 0) break;
      Loan loan{reader, samples, n};
      for (dds_return_t i = 0; i < n; ++i)
        if (infos[i].valid_data && filter_.passes(infos[i].source_timestamp))
          convert_sample(
              [&] {
                return Received<T>{cyclone::from_msg(*static_cast<const typename CycloneType<T>::Msg*>(samples[i])),
                                   writer_of(reader, infos[i].publication_handle)};
              },
              received, malformed_,
              [](const std::string& what, std::uint64_t total) {
                spdlog::warn("bus (cyclone): dropped a malformed sample of {} ({} so far): {}", TopicName<T>::value,
                             total, what);
              });
    }
    queue_.push(std::move(received));
  }

  // Listener callbacks: nothing may escape into Cyclone's thread.
  static void on_data_available(dds_entity_t reader, void* arg) {
    try {
      static_cast<CycloneReader*>(arg)->drain(reader);
    } catch (const std::exception& e) {
      spdlog::error("bus (cyclone): dropping samples of {}: {}", TopicName<T>::value, e.what());
    } catch (...) {
      spdlog::error("bus (cyclone): dropping samples of {}: unknown error", TopicName<T>::value);
    }
  }
  static void on_liveliness_changed(dds_entity_t, const dds_liveliness_changed_status_t, void* arg) { wake(arg); }
  static void on_subscription_matched(dds_entity_t, const dds_subscription_matched_status_t, void* arg) { wake(arg); }
  static void wake(void* arg) {
    try {
      static_cast<CycloneReader*>(arg)->queue_.notify();
    } catch (...) {
      spdlog::error("bus (cyclone): could not wake the reader of {}", TopicName<T>::value);
    }
  }

  std::shared_ptr<Context> context_;
  VolatileFilter filter_;
  MalformedSamples malformed_;  // touched on Cyclone's listener thread only (drain)
  static constexpr std::size_t kMaxRememberedWriters = 4096;
  std::unordered_map<dds_instance_handle_t, WriterId> writers_;  // listener thread only (drain)
  ReaderQueue<T> queue_;
  dds_entity_t subscriber_ = 0;
  dds_entity_t reader_ = 0;
};

class CycloneParticipant final : public ParticipantBase<CycloneParticipant> {
  friend class ParticipantBase<CycloneParticipant>;

 public:
  explicit CycloneParticipant(const BusConfig& config)
      : context_(std::make_shared<Context>(config.domain_id, config.role, config.security, config.peers)) {
    if (config.security.enabled())  // said in the world's and agents' logs (a monitor's stdout stays its output)
      spdlog::log(config.role == Role::kServer ? spdlog::level::debug : spdlog::level::info,
                  "bus: Cyclone DDS participant in domain {}, secured (DDS Security) as {} from {}", config.domain_id,
                  config.security.identity, config.security.dir);
    else
      spdlog::debug("bus: Cyclone DDS participant in domain {}", config.domain_id);
  }
  Vendor vendor() const override { return Vendor::kCyclone; }
  int domain_id() const override { return context_->domain_id(); }
  WriterId id() const override {
    WriterId id;
    dds_guid_t guid;
    if (dds_get_guid(context_->participant(), &guid) == DDS_RETCODE_OK)
      std::copy_n(guid.v, id.prefix.size(), id.prefix.begin());
    return id;
  }

 protected:
  template <typename T>
  std::unique_ptr<Writer<T>> writer(const EndpointOptions& options) {
    return std::make_unique<CycloneWriter<T>>(context_, options);
  }
  template <typename T>
  std::unique_ptr<Reader<T>> reader(const EndpointOptions& options) {
    return std::make_unique<CycloneReader<T>>(context_, options);
  }

 private:
  std::shared_ptr<Context> context_;
};

}  // namespace

std::unique_ptr<Participant> make_cyclone_participant(const BusConfig& config) {
  return std::make_unique<CycloneParticipant>(config);
}

}  // namespace marsala::bus::detail
