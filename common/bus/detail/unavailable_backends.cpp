// Placeholders until the DDS backends are compiled in: asking for them is a clear error, not a link failure.
#include "common/bus/detail/backends.hpp"
#include "common/error.hpp"

namespace marsala::bus::detail {

std::unique_ptr<Participant> make_cyclone_participant(int) {
  throw BusError("the Cyclone DDS backend is not built into this binary");
}
std::unique_ptr<Participant> make_fastdds_participant(int) {
  throw BusError("the Fast DDS backend is not built into this binary");
}

}  // namespace marsala::bus::detail
