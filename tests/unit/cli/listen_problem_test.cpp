#include "marsala/cli/listen_problem.hpp"

#include <gtest/gtest.h>

#include "support/busy_port.hpp"

namespace marsala::cli {
namespace {

TEST(ListenProblem, APortSomeoneListensOnIsInUse) {
  testing::BusyPort busy;
  EXPECT_EQ(listen_problem("127.0.0.1", busy.port()), "the port is in use (another server listens there)");
  busy.release();
  EXPECT_EQ(listen_problem("127.0.0.1", busy.port()), "unknown reason");  // free again: the try succeeds
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
