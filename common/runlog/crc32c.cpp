#include "marsala/runlog/crc32c.hpp"

#include <array>

namespace marsala::runlog {
namespace {

/// The byte table of a reflected CRC-32 of `polynomial`.
constexpr std::array<std::uint32_t, 256> make_table(std::uint32_t polynomial) {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ polynomial : c >> 1;
    table[i] = c;
  }
  return table;
}

constexpr std::array<std::uint32_t, 256> kCastagnoli = make_table(0x82F63B78u);
constexpr std::array<std::uint32_t, 256> kIsoHdlc = make_table(0xEDB88320u);

std::uint32_t reflected_crc(const std::array<std::uint32_t, 256>& table, const void* data, std::size_t size,
                            std::uint32_t crc) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) crc = table[(crc ^ bytes[i]) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

}  // namespace

std::uint32_t crc32c(const void* data, std::size_t size, std::uint32_t crc) {
  return reflected_crc(kCastagnoli, data, size, crc);
}

std::uint32_t crc32_iso(const void* data, std::size_t size, std::uint32_t crc) {
  return reflected_crc(kIsoHdlc, data, size, crc);
}

}  // namespace marsala::runlog
