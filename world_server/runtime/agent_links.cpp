#include "marsala/world_server/runtime/agent_links.hpp"

#include <spdlog/spdlog.h>

#include <exception>
#include <utility>

#include "marsala/core/log_pacing.hpp"

namespace marsala::world_server {

template <typename T>
void write_logged(bus::Writer<T>& writer, const T& sample, const char* what) {
  try {
    writer.write(sample);
  } catch (const std::exception& e) {
    spdlog::error("cannot publish {}: {}", what, e.what());
  }
}

template void write_logged(bus::Writer<protocol::SensorFrame>&, const protocol::SensorFrame&, const char*);
template void write_logged(bus::Writer<protocol::Admission>&, const protocol::Admission&, const char*);
template void write_logged(bus::Writer<protocol::WorldStatus>&, const protocol::WorldStatus&, const char*);
template void write_logged(bus::Writer<protocol::WorldEvent>&, const protocol::WorldEvent&, const char*);

AgentLinks::AgentLinks(bus::Participant& participant, std::shared_ptr<bus::Signal> signal, std::string run_id,
                       std::size_t slots)
    : participant_(participant), signal_(std::move(signal)), run_id_(std::move(run_id)), links_(slots) {}

void AgentLinks::open(const AgentRecord& a, const bus::WriterId& owner) {
  AgentLink& link = links_[a.id - 1];
  if (link.requests && link.session == a.session) return;
  const std::string partition = protocol::partition_for(run_id_, a.id, a.session);
  link = AgentLink{};
  link.session = a.session;
  link.owner = owner;
  link.frames = participant_.create_writer<protocol::SensorFrame>({partition, nullptr, bus::Durability::kVolatile, 64});
  link.requests =
      participant_.create_reader<protocol::ActionRequest>({partition, signal_, bus::Durability::kVolatile, 64});
  spdlog::info("agent {} '{}' ({}) on partition {}", a.id, a.name, a.type.name, partition);
}

bool AgentLinks::connected(std::uint32_t id) const {
  const AgentLink& link = links_[id - 1];
  return link.requests && link.requests->alive_writers() >= 1;
}

bool AgentLinks::ready(std::uint32_t id) const {
  const AgentLink& link = links_[id - 1];
  return link.frames->matched_readers() >= 1 && link.requests->alive_writers() >= 1;
}

LivelinessVerdict AgentLinks::observe(std::uint32_t id, LivelinessWatch::Clock::time_point now) {
  AgentLink& link = links_[id - 1];
  return link.liveliness.observe(link.requests->alive_writers() >= 1, now);
}

bool AgentLinks::bind(std::uint32_t id, const bus::WriterId& from) {
  AgentLink& link = links_[id - 1];
  if (!link.owner.known()) {
    link.owner = from;
    spdlog::info("agent {}: session {:016x} belongs to participant {} from now on", id, link.session,
                 from.to_string());
    return true;
  }
  if (from == link.owner) return true;
  count_foreign(id, from, "hellos");
  return false;
}

void AgentLinks::count_foreign(std::uint32_t id, const bus::WriterId& from, const char* what) {
  AgentLink& link = links_[id - 1];
  if (power_of_ten(++link.foreign))
    spdlog::warn("agent {}: ignoring {} of its session {:016x} from participant {} ({} so far): the session belongs "
                 "to participant {}",
                 id, what, link.session, from.to_string(), link.foreign, link.owner.to_string());
}

std::vector<protocol::ActionRequest> AgentLinks::take(std::uint32_t id) {
  AgentLink& link = links_[id - 1];
  std::vector<protocol::ActionRequest> taken;
  if (!link.requests) return taken;
  for (bus::Received<protocol::ActionRequest>& r : link.requests->take_received()) {
    if (link.owner.known() && r.from != link.owner) {
      count_foreign(id, r.from, "requests");
      continue;
    }
    taken.push_back(std::move(r.sample));
  }
  return taken;
}

void AgentLinks::send(std::uint32_t id, protocol::SensorFrame frame) {
  AgentLink& link = links_[id - 1];
  link.frame = std::move(frame);
  write_logged(*link.frames, *link.frame, "a sensor frame");
  link.resends.first_copy(ResendPolicy::Clock::now(), link.frames->matched_readers());
}

namespace {

// What `link`'s frame writer says about the copies written so far (no writer: nobody to deliver to).
CopyState copy_state(const AgentLink& link) {
  if (!link.frames) return {0, true};
  const int readers = link.frames->matched_readers();
  return {readers, readers < 1 || link.frames->acknowledged()};
}

}  // namespace

bool AgentLinks::resend(std::uint32_t id, std::uint64_t step, ResendPolicy::Clock::time_point now) {
  AgentLink& link = links_[id - 1];
  if (!link.frame || link.frame->step != step) return false;
  const CopyState copy = copy_state(link);
  const Resend what = link.resends.look(now, copy);
  if (what == Resend::kNone) return true;
  write_logged(*link.frames, *link.frame, "a sensor frame");
  link.resends.copied(what, now, copy.readers);
  return true;
}

void AgentLinks::answer_with_frame(std::uint32_t id, ResendPolicy::Clock::time_point now) {
  AgentLink& link = links_[id - 1];
  if (!link.frame || !link.frames) return;
  const CopyState copy = copy_state(link);
  if (world_server::in_flight(copy)) return;
  write_logged(*link.frames, *link.frame, "a sensor frame");
  link.resends.copied(Resend::kAsked, now, copy.readers);
}

bool AgentLinks::in_flight(std::uint32_t id) const { return world_server::in_flight(copy_state(links_[id - 1])); }

}  // namespace marsala::world_server
