#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"

namespace marsala::bus {
namespace {

namespace fs = std::filesystem;

/// An identity folder with the files check_security() asks for (empty: only their presence is checked), keys 0600.
class SecurityCheck : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("marsala_security_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    for (const char* name : {"ca.pem", "governance.p7s", "permissions.p7s", "agent-1.pem", "agent-1.key"})
      std::ofstream(dir_ / name) << "x";
    fs::permissions(dir_ / "agent-1.key", fs::perms::owner_read | fs::perms::owner_write);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void manifest(const std::string& domain) const {
    std::ofstream(dir_ / "manifest") << "# made by make-identities.sh\ndomain=" << domain << "\nagents=3\n";
  }
  /// The message check_security() throws for agent-1 on `domain`, or "" when it accepts the folder.
  std::string refusal(int domain) const {
    try {
      check_security({dir_.string(), "agent-1"}, domain);
      return "";
    } catch (const InvalidArgument& e) {
      return e.what();
    }
  }
  fs::path dir_;
};

TEST_F(SecurityCheck, AFolderWithoutManifestIsTakenOnAnyDomain) {
  EXPECT_EQ(refusal(0), "");
  EXPECT_EQ(refusal(230), "");
}

TEST_F(SecurityCheck, AFolderMadeForOneDomainIsRefusedOnAnotherNamingBoth) {
  manifest("17");
  EXPECT_EQ(refusal(17), "");
  const std::string message = refusal(18);
  EXPECT_NE(message.find("made for domain 17, not domain 18"), std::string::npos) << message;
  EXPECT_NE(message.find(dir_.string()), std::string::npos) << message;
}

TEST_F(SecurityCheck, AFolderMadeForEveryDomainIsTakenOnEach) {
  manifest("0-230");
  EXPECT_EQ(refusal(0), "");
  EXPECT_EQ(refusal(99), "");
}

TEST_F(SecurityCheck, APrivateKeyOthersCanReadIsRefused) {
  fs::permissions(dir_ / "agent-1.key", fs::perms::group_read, fs::perm_options::add);
  const std::string message = refusal(0);
  EXPECT_NE(message.find("agent-1.key is open to other users"), std::string::npos) << message;
}

TEST_F(SecurityCheck, AMissingFileIsNamed) {
  fs::remove(dir_ / "permissions.p7s");
  EXPECT_NE(refusal(0).find("permissions.p7s not found"), std::string::npos);
}

TEST_F(SecurityCheck, AnIdentityMustBeGiven) {
  EXPECT_THROW(check_security({dir_.string(), ""}, 0), InvalidArgument);
  EXPECT_NO_THROW(check_security({}, 0));  // unsecured: nothing to check
}

}  // namespace
}  // namespace marsala::bus
