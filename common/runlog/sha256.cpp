#include "marsala/runlog/sha256.hpp"

#include <openssl/evp.h>

#include <cstring>

#include <fmt/format.h>

#include "marsala/core/error.hpp"

namespace marsala::runlog {

struct Sha256::Context {
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> md{EVP_MD_CTX_new(), &EVP_MD_CTX_free};
};

Sha256::Sha256() : context_(std::make_unique<Context>()) {
  if (!context_->md || EVP_DigestInit_ex(context_->md.get(), EVP_sha256(), nullptr) != 1)
    throw IoError("sha256: libcrypto could not set up a SHA-256 digest");
}

Sha256::~Sha256() = default;

void Sha256::update(const void* data, std::size_t size) {
  if (size > 0 && EVP_DigestUpdate(context_->md.get(), data, size) != 1)
    throw IoError(fmt::format("sha256: libcrypto failed to hash {} bytes", size));
}

std::array<std::uint8_t, 32> Sha256::finish() {
  std::array<std::uint8_t, 32> digest{};
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(context_->md.get(), digest.data(), &length) != 1 || length != digest.size())
    throw IoError("sha256: libcrypto failed to finish the digest");
  return digest;
}

std::string to_hex(const std::array<std::uint8_t, 32>& digest) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(64);
  for (std::uint8_t b : digest) {
    out.push_back(kHex[b >> 4]);
    out.push_back(kHex[b & 15]);
  }
  return out;
}

std::string sha256_hex(const void* data, std::size_t size) {
  Sha256 hash;
  hash.update(data, size);
  return to_hex(hash.finish());
}

std::string terrain_sha256(const Heightmap& terrain) {
  Sha256 hash;
  std::uint8_t bytes[4096];
  std::size_t used = 0;
  for (long long i = 0; i < terrain.size(); ++i) {
    std::uint64_t bits;
    std::memcpy(&bits, terrain.data() + i, sizeof bits);
    for (int b = 0; b < 8; ++b) bytes[used++] = static_cast<std::uint8_t>(bits >> (8 * b));
    if (used == sizeof bytes) {
      hash.update(bytes, used);
      used = 0;
    }
  }
  hash.update(bytes, used);
  return to_hex(hash.finish());
}

}  // namespace marsala::runlog
