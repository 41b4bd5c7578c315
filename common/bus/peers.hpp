#pragma once
// Unicast discovery at given hosts (--peers, MARSALA_PEERS; docs/runtime.md#peers): the addresses the vendors are
// given, resolved once here so that Cyclone and Fast DDS probe the same IPv4 addresses.

#include <string>
#include <vector>

namespace marsala::bus {

/// The IPv4 address of each of `peers` (a dotted-quad address as it is, a host name resolved by the system's
/// resolver), in order, repeats dropped; throws InvalidArgument naming the first peer that is neither an IPv4 address
/// nor a name resolving to one.
std::vector<std::string> resolve_peers(const std::vector<std::string>& peers);

}  // namespace marsala::bus
