#include "marsala/protocol/world_proof.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "marsala/core/error.hpp"

namespace marsala::protocol {
namespace {

std::array<std::uint8_t, 12> prefix(std::uint8_t n) {
  std::array<std::uint8_t, 12> p{};
  p[0] = 1;
  p[11] = n;
  return p;
}

RunKey from_hex(const std::string& hex) {
  RunKey key;
  for (std::size_t i = 0; i < key.seed.size(); ++i)
    key.seed[i] = static_cast<std::uint8_t>(std::stoi(hex.substr(2 * i, 2), nullptr, 16));
  return key;
}

std::string temp_path(const std::string& name) {
  return (::testing::TempDir() + "/world_proof_" + std::to_string(::getpid()) + "_" + name);
}

TEST(WorldProof, ThePublicKeyIsEd25519s) {
  // RFC 8032, section 7.1, TEST 1: the secret key and its public key.
  const RunKey key = from_hex("9d61b19deffd5a60ba844af492ec2cc44449c5697b326919703bac031cae7f60");
  EXPECT_EQ(world_key_of(key), "d75a980182b10ab7d54bfed3c964073a0ee172f3daa62325af021a68f707511a");
}

TEST(WorldProof, AProofHoldsForItsRunAndParticipantOnly) {
  const RunKey key = make_run_key(), other = make_run_key();
  const std::string public_key = world_key_of(key);
  const std::string proof = prove_world(key, "ramp-d7", prefix(1));
  EXPECT_EQ(proof.size(), 128u);
  EXPECT_TRUE(world_proven(public_key, proof, "ramp-d7", prefix(1)));
  EXPECT_FALSE(world_proven(public_key, proof, "ramp-d7", prefix(2)));  // copied to another participant
  EXPECT_FALSE(world_proven(public_key, proof, "ramp-d8", prefix(1)));  // another run
  EXPECT_FALSE(world_proven(world_key_of(other), proof, "ramp-d7", prefix(1)));
  EXPECT_TRUE(world_proven(world_key_of(other), prove_world(other, "ramp-d7", prefix(2)), "ramp-d7", prefix(2)));
  std::string flipped = proof;
  flipped[5] = flipped[5] == '0' ? '1' : '0';
  EXPECT_FALSE(world_proven(public_key, flipped, "ramp-d7", prefix(1)));
  EXPECT_FALSE(world_proven(public_key, "", "ramp-d7", prefix(1)));
  EXPECT_FALSE(world_proven("xyz", proof, "ramp-d7", prefix(1)));
  EXPECT_FALSE(world_proven(public_key, proof.substr(0, 127) + "g", "ramp-d7", prefix(1)));
}

TEST(WorldProof, AKeySavedReadsBackForItsOwnerOnly) {
  const std::string path = temp_path("run.key");
  const RunKey key = make_run_key();
  save_run_key(key, path);
  EXPECT_EQ(load_run_key(path).seed, key.seed);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  std::remove(path.c_str());
}

TEST(WorldProof, ABadKeyFileIsNamed) {
  const std::string path = temp_path("bad.key");
  std::ofstream(path) << "not a key\n";
  try {
    load_run_key(path);
    FAIL() << "no error";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(std::string(e.what()), path + ": not a run key (64 hex digits)");
  }
  std::ofstream(path) << "  " << std::string(64, 'a') << "\n\n";  // white space around the digits is allowed
  EXPECT_EQ(load_run_key(path).seed[0], 0xaa);
  std::remove(path.c_str());
  EXPECT_THROW(load_run_key(path), InvalidArgument);  // missing
}

}  // namespace
}  // namespace marsala::protocol
