#include "marsala/cli/listen_problem.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

namespace marsala::cli {
namespace {

TEST(ListenProblem, APortSomeoneListensOnIsInUse) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof a;
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), length), 0);
  ASSERT_EQ(::listen(fd, 1), 0);
  ASSERT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &length), 0);
  const int port = ntohs(a.sin_port);
  EXPECT_EQ(listen_problem("127.0.0.1", port), "the port is in use (another server listens there)");
  ::close(fd);
  EXPECT_EQ(listen_problem("127.0.0.1", port), "unknown reason");  // free again: the try succeeds
}

TEST(ListenProblem, NamesWhatIsNotANumericAddress) {
  EXPECT_EQ(listen_problem("localhost", 8080), "not a numeric IPv4 or IPv6 address");
  EXPECT_EQ(listen_problem("", 8080), "not a numeric IPv4 or IPv6 address");
}

TEST(ListenProblem, AnAddressOfNoInterfaceHereIsTheSystemsWord) {
  // 192.0.2.1 (TEST-NET-1) is on no interface of a test machine.
  EXPECT_EQ(listen_problem("192.0.2.1", 8080), "Cannot assign requested address");
}

}  // namespace
}  // namespace marsala::cli
