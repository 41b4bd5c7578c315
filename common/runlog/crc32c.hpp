#pragma once
// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), the checksum of every run-log record: it catches a torn
// or corrupted record at the tail of a log cut short by a crash. Also the ISO-HDLC CRC-32 that MCAP files use.

#include <cstddef>
#include <cstdint>

namespace marsala::runlog {

/// CRC-32C of `size` bytes, continuing from `crc` (0 to start). crc32c("123456789") == 0xE3069283.
std::uint32_t crc32c(const void* data, std::size_t size, std::uint32_t crc = 0);

/// CRC-32 (ISO-HDLC, reflected polynomial 0xEDB88320: zlib's, the checksum of MCAP files) of `size` bytes, continuing
/// from `crc` (0 to start). crc32_iso("123456789") == 0xCBF43926.
std::uint32_t crc32_iso(const void* data, std::size_t size, std::uint32_t crc = 0);

}  // namespace marsala::runlog
