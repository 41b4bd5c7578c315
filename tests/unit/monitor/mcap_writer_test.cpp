// The MCAP writer's bytes against the spec (https://mcap.dev/spec) read back by hand here: magic at both ends, the
// footer's offsets landing on the records they name, the summary CRC, the chunk's messages and the statistics. The
// independent reader (npm's @mcap/core) reads whole exports in tests/integration/mcap_export_test.sh.
#include "marsala/monitor/mcap_writer.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <sstream>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/runlog/crc32c.hpp"

namespace marsala::monitor {
namespace {

using runlog::crc32_iso;

std::uint64_t le(const std::string& s, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | static_cast<std::uint8_t>(s[at + i]);
  return v;
}

const std::string kMagic("\x89MCAP0\r\n", 8);

struct Written {
  std::string bytes;
  McapStatistics stats;
};

Written write_two_channels(std::uint64_t chunk_bytes) {
  std::ostringstream out;
  McapWriter w(out, "test", chunk_bytes);
  const auto s = w.add_schema("S", "jsonschema", "{}");
  const auto a = w.add_channel(s, "/a", "json");
  const auto b = w.add_channel(s, "/b", "json");
  w.write_message(a, 10, "{\"k\":1}");
  w.write_message(b, 5, "{\"k\":2}");
  w.write_message(a, 30, "{\"k\":3}");
  w.finish();
  EXPECT_EQ(w.bytes(), out.str().size());
  return {out.str(), w.statistics()};
}

TEST(McapWriter, FooterPointsAtTheSummaryAndItsOffsets) {
  const Written w = write_two_channels(1u << 20);
  const std::string& f = w.bytes;
  ASSERT_GT(f.size(), 64u);
  EXPECT_EQ(f.substr(0, 8), kMagic);
  EXPECT_EQ(f.substr(f.size() - 8), kMagic);
  EXPECT_EQ(f[8], 0x01);  // Header
  const std::size_t footer = f.size() - 8 - 29;  // opcode, length, 20 bytes of content
  ASSERT_EQ(f[footer], 0x02);
  EXPECT_EQ(le(f, footer + 1, 8), 20u);
  const std::uint64_t summary_start = le(f, footer + 9, 8);
  const std::uint64_t offsets_start = le(f, footer + 17, 8);
  EXPECT_EQ(f[summary_start - 13], 0x0F);  // DataEnd right before the summary
  EXPECT_EQ(le(f, summary_start - 4, 4), crc32_iso(f.data(), summary_start - 13));
  EXPECT_EQ(f[summary_start], 0x03);  // the Schema group comes first
  EXPECT_EQ(f[offsets_start], 0x0E);
  EXPECT_EQ(le(f, footer + 25, 4), crc32_iso(f.data() + summary_start, footer + 25 - summary_start));
  // Every SummaryOffset lands on a record of its group's opcode.
  for (std::size_t at = offsets_start; at < footer; at += 9 + 17) {
    ASSERT_EQ(f[at], 0x0E);
    EXPECT_EQ(static_cast<std::uint8_t>(f[le(f, at + 10, 8)]), static_cast<std::uint8_t>(f[at + 9]));
  }
}

TEST(McapWriter, CountsMessagesPerChannelAndTimeRange) {
  const Written w = write_two_channels(1u << 20);
  EXPECT_EQ(w.stats.messages, 3u);
  EXPECT_EQ(w.stats.schemas, 1u);
  EXPECT_EQ(w.stats.channels, 2u);
  EXPECT_EQ(w.stats.chunks, 1u);
  EXPECT_EQ(w.stats.start_ns, 5u);
  EXPECT_EQ(w.stats.end_ns, 30u);
  EXPECT_EQ(w.stats.per_channel.at(0), 2u);
  EXPECT_EQ(w.stats.per_channel.at(1), 1u);
}

TEST(McapWriter, ClosesAChunkOnceItIsFull) {
  // A chunk limit below one message: every message gets its own chunk, each followed by its message index.
  const Written w = write_two_channels(1);
  EXPECT_EQ(w.stats.chunks, 3u);
  std::size_t chunks = 0;
  std::size_t at = 8;
  while (at < w.bytes.size() - 8) {
    const auto op = static_cast<std::uint8_t>(w.bytes[at]);
    if (op == 0x02) break;
    if (op == 0x06) {
      ++chunks;
      EXPECT_EQ(static_cast<std::uint8_t>(w.bytes[at + 9 + le(w.bytes, at + 1, 8)]), 0x07);  // then a MessageIndex
    }
    at += 9 + le(w.bytes, at + 1, 8);
  }
  EXPECT_EQ(chunks, 3u);
}

TEST(McapWriter, RefusesUnknownIdsAndMessagesAfterTheEnd) {
  std::ostringstream out;
  McapWriter w(out, "test");
  EXPECT_THROW(w.add_channel(1, "/x", "json"), InvalidArgument);
  const auto c = w.add_channel(w.add_schema("S", "jsonschema", "{}"), "/x", "json");
  EXPECT_THROW(w.write_message(static_cast<std::uint16_t>(c + 1), 0, "{}"), InvalidArgument);
  w.finish();
  EXPECT_THROW(w.write_message(c, 0, "{}"), InvalidArgument);
}

}  // namespace
}  // namespace marsala::monitor
