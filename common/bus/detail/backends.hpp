#pragma once
// Factories of the backends; make_participant() picks one. Each throws BusError on failure.

#include <memory>

#include "marsala/bus/bus.hpp"

namespace marsala::bus::detail {

std::unique_ptr<Participant> make_inprocess_participant(int domain_id);
std::unique_ptr<Participant> make_cyclone_participant(const BusConfig& config);
std::unique_ptr<Participant> make_fastdds_participant(const BusConfig& config);

}  // namespace marsala::bus::detail
