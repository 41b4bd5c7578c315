#pragma once
// Why a TCP server cannot listen on an address and port: HTTP libraries (cpp-httplib) only say that binding failed,
// and a user needs the reason (the port is in use, the address is not this machine's).

#include <string>

namespace marsala::cli {

/// Why listening on `address`:`port` (a numeric IPv4 or IPv6 address, port 1..65535) fails, found by trying it with
/// a socket of its own: "the port is in use (another server listens there)", "not a numeric IPv4 or IPv6 address",
/// the system's words for any other failure, or "unknown reason" when the try succeeds.
std::string listen_problem(const std::string& address, int port);

}  // namespace marsala::cli
