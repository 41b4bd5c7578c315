#pragma once
// Factories of the backends; make_participant() picks one. Each throws BusError on failure.

#include <memory>

#include "marsala/bus/bus.hpp"

namespace marsala::bus::detail {

std::unique_ptr<Participant> make_inprocess_participant(int domain_id);
std::unique_ptr<Participant> make_cyclone_participant(int domain_id, Role role);
std::unique_ptr<Participant> make_fastdds_participant(int domain_id, Role role);

}  // namespace marsala::bus::detail
