#include "marsala/protocol/world_proof.hpp"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <openssl/rand.h>
#include <sys/stat.h>

#include <cctype>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "marsala/core/error.hpp"

namespace marsala::protocol {
namespace {

struct PkeyFree {
  void operator()(EVP_PKEY* p) const { EVP_PKEY_free(p); }
};
struct MdCtxFree {
  void operator()(EVP_MD_CTX* c) const { EVP_MD_CTX_free(c); }
};
using Pkey = std::unique_ptr<EVP_PKEY, PkeyFree>;
using MdCtx = std::unique_ptr<EVP_MD_CTX, MdCtxFree>;

std::string hex(const std::uint8_t* data, std::size_t size) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string text;
  text.reserve(2 * size);
  for (std::size_t i = 0; i < size; ++i) {
    text += kHex[data[i] >> 4];
    text += kHex[data[i] & 0xf];
  }
  return text;
}

/// The bytes of `text` when it is exactly 2 * size lowercase or uppercase hex digits.
std::optional<std::vector<std::uint8_t>> unhex(const std::string& text, std::size_t size) {
  if (text.size() != 2 * size) return std::nullopt;
  std::vector<std::uint8_t> bytes(size);
  for (std::size_t i = 0; i < 2 * size; ++i) {
    const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(text[i])));
    int v = -1;
    if (c >= '0' && c <= '9') v = c - '0';
    if (c >= 'a' && c <= 'f') v = c - 'a' + 10;
    if (v < 0) return std::nullopt;
    bytes[i / 2] = static_cast<std::uint8_t>(bytes[i / 2] << 4 | v);
  }
  return bytes;
}

/// What the world signs: the run and the participant, so that a proof copied to another participant fails.
std::string statement(const std::string& run_id, const std::array<std::uint8_t, 12>& prefix) {
  return fmt::format("marsala world of run '{}' at participant {}", run_id, hex(prefix.data(), prefix.size()));
}

Pkey private_key(const RunKey& key) {
  Pkey pkey(EVP_PKEY_new_raw_private_key(EVP_PKEY_ED25519, nullptr, key.seed.data(), key.seed.size()));
  if (!pkey) throw Error("run key: libcrypto cannot make an Ed25519 key");
  return pkey;
}

}  // namespace

RunKey make_run_key() {
  RunKey key;
  if (RAND_bytes(key.seed.data(), static_cast<int>(key.seed.size())) != 1)
    throw Error("run key: libcrypto has no randomness (RAND_bytes failed)");
  return key;
}

RunKey load_run_key(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InvalidArgument(fmt::format("{}: cannot be read", path));
  std::ostringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const auto first = s.find_first_not_of(" \t\r\n");
  const auto last = s.find_last_not_of(" \t\r\n");
  s = first == std::string::npos ? std::string() : s.substr(first, last - first + 1);
  const auto bytes = unhex(s, RunKey{}.seed.size());
  if (!bytes) throw InvalidArgument(fmt::format("{}: not a run key (64 hex digits)", path));
  RunKey key;
  std::copy(bytes->begin(), bytes->end(), key.seed.begin());
  return key;
}

void save_run_key(const RunKey& key, const std::string& path) {
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "w");
  if (f == nullptr || ::chmod(tmp.c_str(), 0600) != 0) {
    if (f != nullptr) std::fclose(f);
    throw IoError(fmt::format("run key {}: cannot be written", tmp));
  }
  const std::string text = hex(key.seed.data(), key.seed.size()) + "\n";
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !written || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw IoError(fmt::format("run key {}: cannot be written", path));
  }
}

std::string world_key_of(const RunKey& key) {
  const Pkey pkey = private_key(key);
  std::array<std::uint8_t, 32> raw{};
  std::size_t size = raw.size();
  if (EVP_PKEY_get_raw_public_key(pkey.get(), raw.data(), &size) != 1 || size != raw.size())
    throw Error("run key: libcrypto cannot give the Ed25519 public key");
  return hex(raw.data(), raw.size());
}

std::string prove_world(const RunKey& key, const std::string& run_id, const std::array<std::uint8_t, 12>& prefix) {
  const Pkey pkey = private_key(key);
  const MdCtx ctx(EVP_MD_CTX_new());
  const std::string text = statement(run_id, prefix);
  std::array<std::uint8_t, 64> signature{};
  std::size_t size = signature.size();
  if (!ctx || EVP_DigestSignInit(ctx.get(), nullptr, nullptr, nullptr, pkey.get()) != 1 ||
      EVP_DigestSign(ctx.get(), signature.data(), &size, reinterpret_cast<const unsigned char*>(text.data()),
                     text.size()) != 1 ||
      size != signature.size())
    throw Error("run key: libcrypto cannot sign with Ed25519");
  return hex(signature.data(), signature.size());
}

bool world_proven(const std::string& world_key, const std::string& proof, const std::string& run_id,
                  const std::array<std::uint8_t, 12>& prefix) {
  const auto raw_key = unhex(world_key, 32);
  const auto signature = unhex(proof, 64);
  if (!raw_key || !signature) return false;
  const Pkey pkey(EVP_PKEY_new_raw_public_key(EVP_PKEY_ED25519, nullptr, raw_key->data(), raw_key->size()));
  const MdCtx ctx(EVP_MD_CTX_new());
  if (!pkey || !ctx || EVP_DigestVerifyInit(ctx.get(), nullptr, nullptr, nullptr, pkey.get()) != 1) return false;
  const std::string text = statement(run_id, prefix);
  return EVP_DigestVerify(ctx.get(), signature->data(), signature->size(),
                          reinterpret_cast<const unsigned char*>(text.data()), text.size()) == 1;
}

}  // namespace marsala::protocol
