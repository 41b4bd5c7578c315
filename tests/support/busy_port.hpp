#pragma once
// A loopback TCP port in use, for the tests of servers that must refuse it (the monitor's live view, the world's
// metrics, cli::listen_problem).

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

namespace marsala::testing {

/// A socket listening on a loopback port the system chose: the port is in use while it lives.
class BusyPort {
 public:
  BusyPort() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    socklen_t length = sizeof a;
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || ::listen(fd_, 1) != 0 ||
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &length) != 0)
      ADD_FAILURE() << "cannot make a listening socket";
    port_ = ntohs(a.sin_port);
  }
  ~BusyPort() { release(); }
  BusyPort(const BusyPort&) = delete;
  BusyPort& operator=(const BusyPort&) = delete;

  /// The port [1, 65535].
  int port() const { return port_; }
  /// Stops listening: the port is free again.
  void release() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
  int port_ = 0;
};

}  // namespace marsala::testing
