#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

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

// The unicast profiles need the world's address: Cyclone reads MARSALA_WORLD_ADDRESS itself, Fast DDS 2.9 reads no
// variable, so its template must be written out first (deploy/spawn.sh --profile unicast does).
TEST_F(ProfileTest, AUnicastProfileWithoutTheWorldsAddressIsRefusedSayingWhatIsMissing) {
  const std::string cyclone = source("deploy/dds/cyclone-unicast.xml");
  const std::string fastdds = source("deploy/dds/fastdds-unicast.xml");
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
  EXPECT_NE(refusal(Vendor::kFastDds, fastdds).find("is a template"), std::string::npos);
  ::setenv("MARSALA_WORLD_ADDRESS", "10.0.0.5", 1);
  EXPECT_EQ(refusal(Vendor::kCyclone, cyclone), "");
  EXPECT_NE(refusal(Vendor::kFastDds, fastdds).find("is a template"), std::string::npos);  // the variable is no help
  std::ifstream in(fastdds);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t at; (at = text.find("${MARSALA_WORLD_ADDRESS}")) != std::string::npos;)
    text.replace(at, std::string("${MARSALA_WORLD_ADDRESS}").size(), "10.0.0.5");
  EXPECT_EQ(refusal(Vendor::kFastDds, write("fastdds-unicast-10.0.0.5.xml", text)), "");
  if (saved)
    ::setenv("MARSALA_WORLD_ADDRESS", kept.c_str(), 1);
  else
    ::unsetenv("MARSALA_WORLD_ADDRESS");
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
