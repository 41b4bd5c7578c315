#include <gtest/gtest.h>

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

}  // namespace
}  // namespace marsala::cli
