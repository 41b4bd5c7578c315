#include "marsala/bus/peers.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <memory>

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala::bus {

namespace {

/// `peer` as an IPv4 address: itself when it is one, else its name's first IPv4 address.
std::string resolve_peer(const std::string& peer) {
  in_addr literal{};
  if (inet_pton(AF_INET, peer.c_str(), &literal) == 1) return peer;
  if (!peer.empty() && peer.find_first_not_of("0123456789.") == std::string::npos)
    throw InvalidArgument(fmt::format("DDS peer '{}' (--peers / MARSALA_PEERS) is not an IPv4 address", peer));
  addrinfo hints{};
  hints.ai_family = AF_INET;  // the profiles' transports are UDPv4
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const int rc = getaddrinfo(peer.c_str(), nullptr, &hints, &found);
  if (rc != 0 || found == nullptr)
    throw InvalidArgument(fmt::format("DDS peer '{}' (--peers / MARSALA_PEERS) does not resolve to an IPv4 address: {}",
                                      peer, rc != 0 ? gai_strerror(rc) : "no address"));
  const std::unique_ptr<addrinfo, decltype(&freeaddrinfo)> owned(found, &freeaddrinfo);
  std::array<char, INET_ADDRSTRLEN> text{};
  const auto* address = reinterpret_cast<const sockaddr_in*>(found->ai_addr);
  inet_ntop(AF_INET, &address->sin_addr, text.data(), text.size());
  return text.data();
}

}  // namespace

std::vector<std::string> resolve_peers(const std::vector<std::string>& peers) {
  std::vector<std::string> addresses;
  for (const std::string& peer : peers) {
    std::string address = resolve_peer(peer);
    if (std::find(addresses.begin(), addresses.end(), address) == addresses.end())
      addresses.push_back(std::move(address));
  }
  return addresses;
}

}  // namespace marsala::bus
