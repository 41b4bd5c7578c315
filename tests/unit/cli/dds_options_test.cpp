#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "marsala/cli/command_line.hpp"

namespace marsala::cli {
namespace {

/// Parses `args` with the DDS options under the environment `env` (name, value; value nullptr = unset).
struct Parsed {
  int code = -1;  ///< -1: parsed
  DdsOptions options;
  std::string err;
};

Parsed parse(std::vector<const char*> args, const std::vector<std::pair<const char*, const char*>>& env) {
  for (const auto& [name, value] : env)
    if (value)
      ::setenv(name, value, 1);
    else
      ::unsetenv(name);
  Parsed p;
  CLI::App app{"test"};
  add_dds_options(app, p.options);
  args.insert(args.begin(), "test");
  std::ostringstream out, err;
  if (const auto code = parse_command_line(app, static_cast<int>(args.size()), args.data(), "test", out, err))
    p.code = *code;
  p.err = err.str();
  for (const auto& [name, value] : env) ::unsetenv(name);
  return p;
}

TEST(DdsOptions, FlagsWinOverTheEnvironmentWhichWinsOverDefaults) {
  const Parsed defaults =
      parse({}, {{"MARSALA_DDS", nullptr}, {"MARSALA_DOMAIN", nullptr}, {"MARSALA_DDS_CONFIG", nullptr}});
  EXPECT_EQ(defaults.code, -1);
  EXPECT_EQ(defaults.options.vendor, "cyclone");
  EXPECT_EQ(defaults.options.domain, 0);
  EXPECT_EQ(defaults.options.profile, "");

  const std::vector<std::pair<const char*, const char*>> env = {
      {"MARSALA_DDS", "fastdds"}, {"MARSALA_DOMAIN", "17"}, {"MARSALA_DDS_CONFIG", "/etc/lan.xml"}};
  const Parsed from_env = parse({}, env);
  EXPECT_EQ(from_env.code, -1) << from_env.err;
  EXPECT_EQ(from_env.options.vendor, "fastdds");
  EXPECT_EQ(from_env.options.domain, 17);
  EXPECT_EQ(from_env.options.profile, "/etc/lan.xml");

  const Parsed flags = parse({"--dds", "cyclone", "--domain", "3", "--dds-config", "mine.xml"}, env);
  EXPECT_EQ(flags.code, -1) << flags.err;
  EXPECT_EQ(flags.options.vendor, "cyclone");
  EXPECT_EQ(flags.options.domain, 3);
  EXPECT_EQ(flags.options.profile, "mine.xml");
}

TEST(DdsOptions, BadValuesFromEitherSourceAreUsageErrors) {
  EXPECT_EQ(parse({}, {{"MARSALA_DOMAIN", "300"}}).code, kExitUsage);
  EXPECT_EQ(parse({}, {{"MARSALA_DDS", "opensplice"}}).code, kExitUsage);
  const Parsed bad = parse({"--domain", "-1"}, {});
  EXPECT_EQ(bad.code, kExitUsage);
  EXPECT_NE(bad.err.find("--domain"), std::string::npos) << bad.err;
}

// --peers / MARSALA_PEERS: a comma-separated list, the flag winning over the variable.
TEST(DdsOptions, PeersComeFromTheFlagOrTheEnvironmentAsAList) {
  EXPECT_TRUE(parse({}, {{"MARSALA_PEERS", nullptr}}).options.peers.empty());
  const Parsed from_env = parse({}, {{"MARSALA_PEERS", "10.77.0.1,world.lab"}});
  EXPECT_EQ(from_env.code, -1) << from_env.err;
  EXPECT_EQ(from_env.options.peers, (std::vector<std::string>{"10.77.0.1", "world.lab"}));
  const Parsed flag = parse({"--peers", "192.168.0.7"}, {{"MARSALA_PEERS", "10.77.0.1"}});
  EXPECT_EQ(flag.code, -1) << flag.err;
  EXPECT_EQ(flag.options.peers, std::vector<std::string>{"192.168.0.7"});
}

// A malformed address is a usage error naming it, from the flag or the variable.
TEST(DdsOptions, AMalformedPeerIsAUsageErrorNamingIt) {
  for (const char* bad : {"10.0.0.256", "10.0.0", "010.0.0.1", "world:7400", "-world", "a..b", "world.", "ho st",
                          "[::1]"}) {
    const Parsed flag = parse({"--peers", bad}, {});
    EXPECT_EQ(flag.code, kExitUsage) << bad;
    EXPECT_NE(flag.err.find("--peers"), std::string::npos) << flag.err;
    EXPECT_EQ(std::count(flag.err.begin(), flag.err.end(), '\n'), 1) << flag.err;
  }
  const Parsed env = parse({}, {{"MARSALA_PEERS", "10.77.0.1,10.77.0.999"}});
  EXPECT_EQ(env.code, kExitUsage);
  EXPECT_NE(env.err.find("'10.77.0.999'"), std::string::npos) << env.err;
}

TEST(DdsOptions, PeerAddressesAreDottedQuadsOrHostNames) {
  for (const char* good : {"10.77.0.1", "0.0.0.0", "255.255.255.255", "localhost", "world-1.lab.example", "h1", "3com"})
    EXPECT_TRUE(is_peer_address(good)) << good;
  for (const char* bad : {"", "256.1.1.1", "1.2.3", "1.2.3.4.5", "01.2.3.4", "a_b", "x-", ".x", "x..y",
                          "host:7400", "fe80::1"})
    EXPECT_FALSE(is_peer_address(bad)) << bad;
  EXPECT_FALSE(is_peer_address(std::string(64, 'a')));
  EXPECT_TRUE(is_peer_address(std::string(63, 'a')));
}

}  // namespace
}  // namespace marsala::cli
