#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "marsala/bus/peers.hpp"
#include "marsala/core/error.hpp"

namespace marsala::bus {
namespace {

TEST(ResolvePeers, AddressesStayAsTheyAreInOrderWithoutRepeats) {
  EXPECT_EQ(resolve_peers({}), std::vector<std::string>{});
  EXPECT_EQ(resolve_peers({"10.77.0.1", "192.168.1.20", "10.77.0.1"}),
            (std::vector<std::string>{"10.77.0.1", "192.168.1.20"}));
}

// Names go through the system's resolver; "localhost" is in every /etc/hosts this runs with.
TEST(ResolvePeers, ANameBecomesItsIpv4AddressAndRepeatsOfItAreDropped) {
  EXPECT_EQ(resolve_peers({"localhost", "127.0.0.1"}), std::vector<std::string>{"127.0.0.1"});
}

TEST(ResolvePeers, ANumericPeerThatIsNoIpv4AddressIsRefusedByName) {
  for (const char* bad : {"10.0.0.300", "10.1", "1.2.3.4.5"}) {
    try {
      resolve_peers({"10.0.0.1", bad});
      ADD_FAILURE() << bad << ": no throw";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("--peers"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace marsala::bus
