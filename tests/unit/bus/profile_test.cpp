#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"

namespace marsala::bus {
namespace {

namespace fs = std::filesystem;

/// The vendors' variables cleared for the test, restored after it.
class ProfileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* name : kVariables) {
      const char* v = std::getenv(name);
      saved_.push_back(v ? std::optional<std::string>(v) : std::nullopt);
      ::unsetenv(name);
    }
    dir_ = fs::temp_directory_path() / ("marsala_profile_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    for (std::size_t i = 0; i < saved_.size(); ++i)
      if (saved_[i])
        ::setenv(kVariables[i], saved_[i]->c_str(), 1);
      else
        ::unsetenv(kVariables[i]);
    fs::remove_all(dir_);
  }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  static std::string source(const std::string& rel) {
    const char* root = std::getenv("MARSALA_SOURCE_DIR");
    return (fs::path(root ? root : ".") / rel).string();
  }

  static constexpr const char* kVariables[] = {"CYCLONEDDS_URI", "FASTRTPS_DEFAULT_PROFILES_FILE"};
  std::vector<std::optional<std::string>> saved_;
  fs::path dir_;
};

TEST_F(ProfileTest, AGivenProfileMustBeOneOfThatVendor) {
  const std::string cyclone = source("deploy/dds/cyclone-lan.xml"), fastdds = source("deploy/dds/fastdds-lan.xml");
  EXPECT_EQ(resolve_profile(Vendor::kCyclone, cyclone), fs::absolute(cyclone).string());
  EXPECT_EQ(resolve_profile(Vendor::kFastDds, fastdds), fs::absolute(fastdds).string());
  try {
    resolve_profile(Vendor::kCyclone, fastdds);
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("is not a Cyclone DDS profile"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("it is a Fast DDS one"), std::string::npos) << e.what();
  }
  EXPECT_THROW(resolve_profile(Vendor::kFastDds, cyclone), InvalidArgument);
  EXPECT_THROW(resolve_profile(Vendor::kCyclone, (dir_ / "missing.xml").string()), InvalidArgument);
  EXPECT_THROW(resolve_profile(Vendor::kFastDds, write("junk.xml", "ncols 3\n")), InvalidArgument);
  EXPECT_EQ(resolve_profile(Vendor::kInProcess, "anything"), "");
}

// An older unicast profile holding the world's address as a variable: Cyclone reads MARSALA_WORLD_ADDRESS itself,
// Fast DDS 2.9 reads no variable; each refusal says to give --peers instead (the shipped ones hold no address).
TEST_F(ProfileTest, AProfileStillHoldingTheWorldsAddressVariableIsRefusedPointingToPeers) {
  const std::string cyclone = write("cyclone-old.xml",
                                    "<CycloneDDS><Domain><Discovery><Peers><Peer address=\"${MARSALA_WORLD_ADDRESS}\"/>"
                                    "</Peers></Discovery></Domain></CycloneDDS>\n");
  const std::string fastdds = write("fastdds-old.xml",
                                    "<dds><profiles><participant><rtps><builtin><initialPeersList><locator><udpv4>"
                                    "<address>${MARSALA_WORLD_ADDRESS}</address></udpv4></locator></initialPeersList>"
                                    "</builtin></rtps></participant></profiles></dds>\n");
  const char* saved = std::getenv("MARSALA_WORLD_ADDRESS");
  const std::string kept = saved ? saved : "";
  ::unsetenv("MARSALA_WORLD_ADDRESS");
  const auto refusal = [](Vendor v, const std::string& path) -> std::string {
    try {
      resolve_profile(v, path);
      return "";
    } catch (const InvalidArgument& e) {
      return e.what();
    }
  };
  EXPECT_NE(refusal(Vendor::kCyclone, cyclone).find("needs MARSALA_WORLD_ADDRESS"), std::string::npos);
  EXPECT_NE(refusal(Vendor::kCyclone, cyclone).find("--peers"), std::string::npos);
  EXPECT_NE(refusal(Vendor::kFastDds, fastdds).find("is a template"), std::string::npos);
  EXPECT_NE(refusal(Vendor::kFastDds, fastdds).find("--peers"), std::string::npos);
  ::setenv("MARSALA_WORLD_ADDRESS", "10.0.0.5", 1);
  EXPECT_EQ(refusal(Vendor::kCyclone, cyclone), "");
  EXPECT_NE(refusal(Vendor::kFastDds, fastdds).find("is a template"), std::string::npos);  // the variable is no help
  for (const char* shipped : {"deploy/dds/cyclone-unicast.xml", "deploy/dds/fastdds-unicast.xml"})
    EXPECT_EQ(refusal(std::string(shipped).find("cyclone") != std::string::npos ? Vendor::kCyclone : Vendor::kFastDds,
                      source(shipped)),
              "")
        << shipped;
  if (saved)
    ::setenv("MARSALA_WORLD_ADDRESS", kept.c_str(), 1);
  else
    ::unsetenv("MARSALA_WORLD_ADDRESS");
}

/// The shipped slow-link profile with the rate property `name`'s value replaced by `value`.
std::string slow_profile_with(const std::string& name, const std::string& value) {
  const char* root = std::getenv("MARSALA_SOURCE_DIR");
  std::ifstream in(fs::path(root ? root : ".") / "deploy/dds/fastdds-slow.xml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string open = "<name>" + name + "</name><value>";
  const std::size_t at = text.find(open);
  if (at == std::string::npos) return {};
  const std::size_t from = at + open.size();
  return text.replace(from, text.find("</value>", from) - from, value);
}

// A bad rate limit in a Fast DDS profile (docs/runtime.md#slow-links) is refused by the checks made before anything
// runs, with the property, the value and the file named; the shipped one passes.
TEST_F(ProfileTest, ABadRateLimitInAFastDdsProfileIsRefusedNamingPropertyAndFile) {
  struct Case {
    std::string name, value;
  };
  const std::vector<Case> bad{{"marsala.rate.bytes_per_period", "lots"},
                              {"marsala.rate.bytes_per_period", "1000"},  // below one datagram
                              {"marsala.rate.period_ms", "0"},
                              {"marsala.rate.period_ms", "-40"}};
  int n = 0;
  for (const Case& c : bad) {
    const std::string text = slow_profile_with(c.name, c.value);
    ASSERT_FALSE(text.empty()) << c.name << " not in fastdds-slow.xml";
    const std::string file = write("bad-rate-" + std::to_string(n++) + ".xml", text);
    try {
      check_config({Vendor::kFastDds, 7, file});
      ADD_FAILURE() << c.name << "=" << c.value << ": no throw";
    } catch (const InvalidArgument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(file), std::string::npos) << what;
      EXPECT_NE(what.find(c.name), std::string::npos) << what;
      EXPECT_NE(what.find("'" + c.value + "'"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
    }
  }
  // The same through the vendor's own variable, no profile given.
  const std::string bad_env = write("bad-rate-env.xml", slow_profile_with("marsala.rate.period_ms", "soon"));
  ::setenv("FASTRTPS_DEFAULT_PROFILES_FILE", bad_env.c_str(), 1);
  EXPECT_THROW(check_config({Vendor::kFastDds, 7}), InvalidArgument);
  EXPECT_NO_THROW(check_config({Vendor::kCyclone, 7}));  // the other vendor's variable is none of Cyclone's business
  ::unsetenv("FASTRTPS_DEFAULT_PROFILES_FILE");
  EXPECT_NO_THROW(check_config({Vendor::kFastDds, 7, source("deploy/dds/fastdds-slow.xml")}));
  EXPECT_NO_THROW(check_config({Vendor::kFastDds, 7, source("deploy/dds/fastdds-lan.xml")}));  // no rate limit
}

// With peers (and no profile given nor set): the shipped unicast profile, every interface and no multicast.
TEST_F(ProfileTest, WithPeersTheDefaultIsTheShippedUnicastProfile) {
  EXPECT_EQ(fs::path(resolve_profile(Vendor::kCyclone, "", true)).filename(), "cyclone-unicast.xml");
  EXPECT_EQ(fs::path(resolve_profile(Vendor::kFastDds, "", true)).filename(), "fastdds-unicast.xml");
  const std::string lan = source("deploy/dds/cyclone-lan.xml");
  EXPECT_EQ(resolve_profile(Vendor::kCyclone, lan, true), fs::absolute(lan).string());  // a given one still wins
  ::setenv("FASTRTPS_DEFAULT_PROFILES_FILE", "/somewhere/else.xml", 1);
  EXPECT_EQ(resolve_profile(Vendor::kFastDds, "", true), "");  // and so does the vendor's variable
}

// Without a given profile: the vendor's own variable applies when set, else the shipped loopback profile.
TEST_F(ProfileTest, TheDefaultIsTheVendorsVariableElseTheShippedLoopbackProfile) {
  const std::string cyclone_lo = resolve_profile(Vendor::kCyclone, "");
  const std::string fastdds_lo = resolve_profile(Vendor::kFastDds, "");
  EXPECT_EQ(fs::path(cyclone_lo).filename(), "cyclone-lo.xml");
  EXPECT_EQ(fs::path(fastdds_lo).filename(), "fastdds-lo.xml");
  EXPECT_TRUE(fs::is_regular_file(cyclone_lo));
  ::setenv("CYCLONEDDS_URI", "file:///somewhere/else.xml", 1);
  EXPECT_EQ(resolve_profile(Vendor::kCyclone, ""), "");
  EXPECT_EQ(fs::path(resolve_profile(Vendor::kFastDds, "")).filename(), "fastdds-lo.xml");  // the other vendor's
}

}  // namespace
}  // namespace marsala::bus
