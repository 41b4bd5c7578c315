// The in-process backend: participants of one domain in one process share a hub per message type.
// Same semantics as the DDS backends where tests rely on them: partitions isolate, delivery is reliable and
// in order, transient-local writers replay their latest sample to late readers, and a writer that is
// destroyed no longer counts as alive.

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <tuple>

#include "marsala/bus/detail/backends.hpp"
#include "marsala/bus/detail/participant_base.hpp"
#include "marsala/bus/detail/reader_queue.hpp"

namespace marsala::bus::detail {
namespace {

template <typename T>
class Hub;

template <typename T>
class InProcessReader final : public Reader<T> {
 public:
  InProcessReader(std::shared_ptr<Hub<T>> hub, EndpointOptions options)
      : hub_(std::move(hub)), options_(options), queue_(options_.signal, options_.on_data) {}
  ~InProcessReader() override { hub_->remove_reader(this); }

  std::vector<Received<T>> take_received() override { return queue_.take(); }
  int alive_writers() const override { return hub_->writers_in(options_.partition); }

  /// Queues the sample and calls the on_data handler on the writer's thread, as a DDS backend calls it on its own
  /// (else wakes the reader's Signal).
  void deliver(const Received<T>& sample) { queue_.push({sample}); }
  void notify() const { queue_.notify(); }
  const EndpointOptions& options() const { return options_; }

 private:
  std::shared_ptr<Hub<T>> hub_;
  EndpointOptions options_;
  ReaderQueue<T> queue_;
};

template <typename T>
class InProcessWriter final : public Writer<T> {
 public:
  InProcessWriter(std::shared_ptr<Hub<T>> hub, EndpointOptions options, WriterId from)
      : hub_(std::move(hub)), options_(options), from_(from) {}
  ~InProcessWriter() override { hub_->remove_writer(this); }
  void write(const T& sample) override { hub_->publish(this, Received<T>{sample, from_}); }
  int matched_readers() const override { return hub_->readers_in(options_.partition); }
  const EndpointOptions& options() const { return options_; }

 private:
  std::shared_ptr<Hub<T>> hub_;
  EndpointOptions options_;
  WriterId from_;
};

/// All endpoints of one message type in one domain.
template <typename T>
class Hub {
 public:
  void add_reader(InProcessReader<T>* reader) {
    // The replay is delivered under the hub lock, so a concurrent publish cannot overtake it.
    std::lock_guard<std::mutex> lock(mutex_);
    readers_.push_back(reader);
    if (reader->options().durability == Durability::kTransientLocal)
      for (const auto& [writer, latest] : latest_)
        if (writer->options().partition == reader->options().partition) reader->deliver(latest);
    notify_partition(reader->options().partition);
  }
  void remove_reader(InProcessReader<T>* reader) {
    std::lock_guard<std::mutex> lock(mutex_);
    readers_.erase(std::remove(readers_.begin(), readers_.end(), reader), readers_.end());
  }
  void add_writer(InProcessWriter<T>* writer) {
    std::lock_guard<std::mutex> lock(mutex_);
    writers_.push_back(writer);
    notify_partition(writer->options().partition);
  }
  void remove_writer(InProcessWriter<T>* writer) {
    std::lock_guard<std::mutex> lock(mutex_);
    writers_.erase(std::remove(writers_.begin(), writers_.end(), writer), writers_.end());
    latest_.erase(writer);
    notify_partition(writer->options().partition);
  }
  void publish(InProcessWriter<T>* writer, const Received<T>& sample) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (writer->options().durability == Durability::kTransientLocal) latest_[writer] = sample;
    for (InProcessReader<T>* reader : readers_)
      if (reader->options().partition == writer->options().partition) reader->deliver(sample);
  }
  int writers_in(const std::string& partition) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<int>(
        std::count_if(writers_.begin(), writers_.end(), [&](auto* w) { return w->options().partition == partition; }));
  }
  int readers_in(const std::string& partition) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<int>(
        std::count_if(readers_.begin(), readers_.end(), [&](auto* r) { return r->options().partition == partition; }));
  }

 private:
  void notify_partition(const std::string& partition) const {
    for (InProcessReader<T>* reader : readers_)
      if (reader->options().partition == partition) reader->notify();
  }

  mutable std::mutex mutex_;
  std::vector<InProcessReader<T>*> readers_;
  std::vector<InProcessWriter<T>*> writers_;
  std::map<InProcessWriter<T>*, Received<T>> latest_;
};

/// One hub per message type for one domain.
struct Domain {
  std::tuple<std::shared_ptr<Hub<AgentHello>>, std::shared_ptr<Hub<Admission>>, std::shared_ptr<Hub<SensorFrame>>,
             std::shared_ptr<Hub<ActionRequest>>, std::shared_ptr<Hub<WorldStatus>>, std::shared_ptr<Hub<WorldEvent>>>
      hubs{std::make_shared<Hub<AgentHello>>(),  std::make_shared<Hub<Admission>>(),
           std::make_shared<Hub<SensorFrame>>(), std::make_shared<Hub<ActionRequest>>(),
           std::make_shared<Hub<WorldStatus>>(), std::make_shared<Hub<WorldEvent>>()};
};

std::shared_ptr<Domain> domain(int domain_id) {
  static std::mutex mutex;
  static std::map<int, std::weak_ptr<Domain>> domains;
  std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<Domain> d = domains[domain_id].lock();
  if (!d) {
    d = std::make_shared<Domain>();
    domains[domain_id] = d;
  }
  return d;
}

class InProcessParticipant final : public ParticipantBase<InProcessParticipant> {
  friend class ParticipantBase<InProcessParticipant>;

 public:
  explicit InProcessParticipant(int domain_id) : domain_id_(domain_id), domain_(domain(domain_id)), id_(next_id()) {}
  Vendor vendor() const override { return Vendor::kInProcess; }
  int domain_id() const override { return domain_id_; }
  WriterId id() const override { return id_; }

 protected:
  template <typename T>
  std::unique_ptr<Writer<T>> writer(const EndpointOptions& options) {
    auto hub = std::get<std::shared_ptr<Hub<T>>>(domain_->hubs);
    auto w = std::make_unique<InProcessWriter<T>>(hub, options, id_);
    hub->add_writer(w.get());
    return w;
  }
  template <typename T>
  std::unique_ptr<Reader<T>> reader(const EndpointOptions& options) {
    auto hub = std::get<std::shared_ptr<Hub<T>>>(domain_->hubs);
    auto r = std::make_unique<InProcessReader<T>>(hub, options);
    hub->add_reader(r.get());
    return r;
  }

 private:
  /// A prefix no other participant of this process has: 0x01, then a counter.
  static WriterId next_id() {
    static std::atomic<std::uint64_t> counter{0};
    const std::uint64_t n = ++counter;
    WriterId id;
    id.prefix[0] = 0x01;
    for (int i = 0; i < 8; ++i) id.prefix[4 + i] = static_cast<std::uint8_t>(n >> (8 * (7 - i)));
    return id;
  }

  int domain_id_;
  std::shared_ptr<Domain> domain_;
  WriterId id_;
};

}  // namespace

std::unique_ptr<Participant> make_inprocess_participant(int domain_id) {
  return std::make_unique<InProcessParticipant>(domain_id);
}

}  // namespace marsala::bus::detail
