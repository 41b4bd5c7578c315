#pragma once
// SHA-256 (FIPS 180-4), for fingerprints of terrains: two runs that end with the same heights bit for bit print the
// same digest.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "marsala/core/heightmap.hpp"

namespace marsala::world_server {

/// Incremental SHA-256.
class Sha256 {
 public:
  Sha256();
  /// Appends `size` bytes.
  void update(const void* data, std::size_t size);
  /// The digest of everything appended; the object is spent afterwards.
  std::array<std::uint8_t, 32> finish();

 private:
  void block(const std::uint8_t* p);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buffer_{};
  std::size_t buffered_ = 0;
  std::uint64_t total_bytes_ = 0;
};

/// Lowercase hex of a digest (64 characters).
std::string to_hex(const std::array<std::uint8_t, 32>& digest);

/// Hex SHA-256 of `size` bytes.
std::string sha256_hex(const void* data, std::size_t size);

/// Hex SHA-256 of the heights as little-endian IEEE doubles, row-major (row 0 first).
std::string terrain_sha256(const Heightmap& terrain);

}  // namespace marsala::world_server
