#pragma once
// Factories of the backends; make_participant() picks one. Each throws BusError on failure.

#include <memory>
#include <string>

#include "marsala/bus/bus.hpp"

namespace marsala::bus::detail {

std::unique_ptr<Participant> make_inprocess_participant(int domain_id);
std::unique_ptr<Participant> make_cyclone_participant(const BusConfig& config);
std::unique_ptr<Participant> make_fastdds_participant(const BusConfig& config);
/// Throws InvalidArgument naming the Fast DDS profile file `path` when Fast DDS cannot load it or a MARSala property of
/// its default participant profile is not valid (the rate limit, docs/runtime.md#slow-links).
void check_fastdds_profile(const std::string& path);

}  // namespace marsala::bus::detail
