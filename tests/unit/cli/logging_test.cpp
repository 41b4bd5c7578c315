#include "marsala/cli/logging.hpp"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <sstream>
#include <string>

#include "marsala/cli/version.hpp"
#include "marsala/core/error.hpp"

namespace marsala::cli {
namespace {

// 2026-11-24T06:26:08.123Z
const std::chrono::system_clock::time_point kTime =
    std::chrono::system_clock::time_point(std::chrono::milliseconds(1795501568123LL));

TEST(LogLine, TextCarriesTimeLevelProcessAgentAndPid) {
  EXPECT_EQ(format_log_line(LogFormat::kText, "agent", 3, 4250, kTime, "warn", "ignoring a stale frame"),
            "2026-11-24T06:26:08.123Z warn  agent-3[4250]: ignoring a stale frame");
  EXPECT_EQ(format_log_line(LogFormat::kText, "world", 0, 42, kTime, "info", "run over"),
            "2026-11-24T06:26:08.123Z info  world[42]: run over");
}

TEST(LogLine, JsonIsOneObjectWithTheSameFields) {
  EXPECT_EQ(format_log_line(LogFormat::kJson, "agent", 3, 4250, kTime, "info", "say \"hi\"\n"),
            "{\"time\":\"2026-11-24T06:26:08.123Z\",\"level\":\"info\",\"process\":\"agent\",\"agent_id\":3,"
            "\"pid\":4250,\"msg\":\"say \\\"hi\\\"\\n\"}");
  EXPECT_EQ(format_log_line(LogFormat::kJson, "world", 0, 1, kTime, "error", "x"),
            "{\"time\":\"2026-11-24T06:26:08.123Z\",\"level\":\"error\",\"process\":\"world\",\"agent_id\":null,"
            "\"pid\":1,\"msg\":\"x\"}");
}

TEST(LogLine, JsonEscapesControlsAndReplacesInvalidUtf8) {
  const auto msg = [](const std::string& message) {
    const std::string line = format_log_line(LogFormat::kJson, "world", 0, 1, kTime, "info", message);
    const std::string head = ",\"msg\":";
    return line.substr(line.find(head) + head.size(), line.size() - line.find(head) - head.size() - 1);
  };
  EXPECT_EQ(msg("a\tb\\c\x01"), "\"a\\tb\\\\c\\u0001\"");
  EXPECT_EQ(msg("caf\xc3\xa9"), "\"caf\xc3\xa9\"");          // valid UTF-8 kept
  EXPECT_EQ(msg("bad\xff!"), "\"bad\xef\xbf\xbd!\"");          // a stray byte becomes U+FFFD
  EXPECT_EQ(msg("\xc0\xaf"), "\"\xef\xbf\xbd\xef\xbf\xbd\"");  // an overlong form too
  EXPECT_EQ(msg("\xe2\x82x"), "\"\xef\xbf\xbdx\"");             // a cut sequence is one U+FFFD
}

TEST(LogLine, JsonReplacesInvalidUtf8InTheMessage) {
  EXPECT_EQ(format_log_line(LogFormat::kJson, "monitor", 0, 7, kTime, "warn", "run \xff\t"),
            "{\"time\":\"2026-11-24T06:26:08.123Z\",\"level\":\"warn\",\"process\":\"monitor\",\"agent_id\":null,"
            "\"pid\":7,\"msg\":\"run \xef\xbf\xbd\\t\"}");
}

TEST(Logging, JsonRecordsGoToTheStreamAndTheScopeRestoresTheLogger) {
  const auto before = spdlog::default_logger();
  std::ostringstream out;
  {
    LogOptions options;
    options.format = "json";
    const LoggingScope scope("monitor", 0, options, &out);
    EXPECT_EQ(log_format(), LogFormat::kJson);
    spdlog::info("hello {}", 1);
    spdlog::debug("not shown at level info");
    set_log_agent_id(7);
    spdlog::warn("as agent 7");
  }
  EXPECT_EQ(spdlog::default_logger(), before);
  EXPECT_EQ(log_format(), LogFormat::kText);
  const std::string text = out.str();
  EXPECT_NE(text.find("\"level\":\"info\",\"process\":\"monitor\",\"agent_id\":null,"), std::string::npos) << text;
  EXPECT_NE(text.find("\"msg\":\"hello 1\"}\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\"agent_id\":7,"), std::string::npos) << text;
  EXPECT_EQ(text.find("not shown"), std::string::npos) << text;
}

TEST(Logging, BadFormatOrLevelIsRefusedNamingIt) {
  LogOptions bad_format;
  bad_format.format = "xml";
  EXPECT_THROW(setup_logging("world", 0, bad_format), InvalidArgument);
  LogOptions bad_level;
  bad_level.level = "loud";
  EXPECT_THROW(setup_logging("world", 0, bad_level), InvalidArgument);
}

TEST(Version, NamesTheProgramVersionAndRevision) {
  const std::string text = version_text("marsala-x");
  EXPECT_EQ(text, std::string("marsala-x ") + project_version() + " (git " + git_revision() + ")");
  const std::string revision = git_revision();
  EXPECT_TRUE(revision == "unknown" || revision.size() >= 12) << revision;
}

}  // namespace
}  // namespace marsala::cli
