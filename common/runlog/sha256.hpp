#pragma once
// SHA-256 fingerprints of terrains (OpenSSL's libcrypto): two runs that end with the same heights bit for bit print
// the same digest.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "marsala/core/heightmap.hpp"

namespace marsala::runlog {

/// Incremental SHA-256 (FIPS 180-4).
class Sha256 {
 public:
  /// Throws IoError when libcrypto cannot set up a digest.
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  /// Appends `size` bytes.
  void update(const void* data, std::size_t size);
  /// The digest of everything appended; the object is spent afterwards.
  std::array<std::uint8_t, 32> finish();

 private:
  struct Context;
  std::unique_ptr<Context> context_;
};

/// Lowercase hex of a digest (64 characters).
std::string to_hex(const std::array<std::uint8_t, 32>& digest);

/// Hex SHA-256 of `size` bytes.
std::string sha256_hex(const void* data, std::size_t size);

/// Hex SHA-256 of the heights as little-endian IEEE doubles, row-major (row 0 first).
std::string terrain_sha256(const Heightmap& terrain);

}  // namespace marsala::runlog
