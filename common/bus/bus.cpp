#include "marsala/bus/bus.hpp"

#include "marsala/bus/detail/backends.hpp"
#include "marsala/core/enum_names.hpp"
#include "marsala/core/error.hpp"

namespace marsala::bus {

namespace {
constexpr EnumName<Vendor> kVendorNames[] = {
    {Vendor::kCyclone, "cyclone"}, {Vendor::kFastDds, "fastdds"}, {Vendor::kInProcess, "inprocess"}};
}  // namespace

std::string to_string(Vendor v) { return enum_to_string(kVendorNames, v); }

Vendor vendor_from_string(const std::string& name) { return enum_from_string(kVendorNames, name, "DDS vendor"); }

void Signal::notify() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = true;
  }
  cv_.notify_all();
}

bool Signal::wait_for(std::chrono::nanoseconds timeout) {
  return wait_until(std::chrono::steady_clock::now() + timeout);
}

bool Signal::wait_until(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool notified = cv_.wait_until(lock, deadline, [this] { return pending_; });
  pending_ = false;
  return notified;
}

std::unique_ptr<Participant> make_participant(const BusConfig& config) {
  if (config.domain_id < 0 || config.domain_id > 232)
    throw InvalidArgument("DDS domain id must be in 0..232, got " + std::to_string(config.domain_id));
  switch (config.vendor) {
    case Vendor::kInProcess: return detail::make_inprocess_participant(config.domain_id);
    case Vendor::kCyclone: return detail::make_cyclone_participant(config.domain_id);
    case Vendor::kFastDds: return detail::make_fastdds_participant(config.domain_id);
  }
  throw InvalidArgument("unknown DDS vendor");
}

}  // namespace marsala::bus
