#include "marsala/runlog/sha256.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace marsala::runlog {
namespace {

std::string hex_of(const std::string& s) { return sha256_hex(s.data(), s.size()); }

TEST(Sha256, StandardTestVectors) {
  // FIPS 180-4 / NIST CAVP examples.
  EXPECT_EQ(hex_of(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(hex_of("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(hex_of("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(
      hex_of("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnopjklmnopqklmnopqrlmnopqrsmnopqrst"
             "nopqrstu"),
      "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
  EXPECT_EQ(hex_of(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, IncrementalUpdatesInAnyChunkingGiveTheSameDigest) {
  std::string message;
  for (int i = 0; i < 1000; ++i) message.push_back(static_cast<char>(i * 37 + 11));
  const std::string whole = hex_of(message);
  for (std::size_t chunk : {1u, 3u, 55u, 56u, 63u, 64u, 65u, 127u, 999u}) {
    Sha256 hash;
    for (std::size_t at = 0; at < message.size(); at += chunk)
      hash.update(message.data() + at, std::min(chunk, message.size() - at));
    EXPECT_EQ(to_hex(hash.finish()), whole) << "chunk " << chunk;
  }
}

TEST(Sha256, TerrainDigestIsOfLittleEndianDoublesRowMajor) {
  GridGeometry g;
  g.rows = 2;
  g.cols = 3;
  Heightmap h(g, 0.0);
  const double values[6] = {1.0, -2.5, 0.1, 1e-300, 3.0, 1.5};
  for (int i = 0; i < 6; ++i) h.data()[i] = values[i];
  std::vector<unsigned char> bytes;
  for (double v : values) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, 8);
    for (int b = 0; b < 8; ++b) bytes.push_back(static_cast<unsigned char>(bits >> (8 * b)));
  }
  EXPECT_EQ(bytes[0], 0x00);  // 1.0 = 0x3ff0000000000000: its low byte first
  EXPECT_EQ(bytes[7], 0x3f);
  EXPECT_EQ(terrain_sha256(h), sha256_hex(bytes.data(), bytes.size()));
  h(1, 2) = std::nextafter(1.5, 2.0);
  EXPECT_NE(terrain_sha256(h), sha256_hex(bytes.data(), bytes.size()));
  // One zero-height cell: eight zero bytes.
  GridGeometry one;
  one.rows = 1;
  one.cols = 1;
  const unsigned char zeros[8] = {};
  EXPECT_EQ(terrain_sha256(Heightmap(one, 0.0)), sha256_hex(zeros, 8));
  EXPECT_EQ(sha256_hex(zeros, 8), "af5570f5a1810b7af78caf4bc70a660f0df51e42baf91d4de5b2328de0e83dfc");
}

}  // namespace
}  // namespace marsala::runlog
