#pragma once
// The run key and the world's proof (docs/runtime.md#who-wrote-it). Without DDS Security anyone on the domain may
// speak in the world's name, but no one can write under another participant's GUID prefix through a DDS API. So the
// world signs, once per process, "I am the world of run R at participant P" with the run key (an Ed25519 key kept
// in the run folder as run.key, reloaded by a resumed world), and sends the public key and that signature in its
// Admission and WorldStatus. A receiver believes a participant's admissions and statuses only when the signature
// holds for that participant's prefix under the run's public key: known beforehand (an agent or monitor given the
// run key), or pinned from the first world that proved itself (then a resumed world, a new participant, still
// proves the same key, and a stranger cannot).

#include <array>
#include <cstdint>
#include <string>

namespace marsala::protocol {

/// The secret of one run: an Ed25519 private key (its 32-byte seed).
struct RunKey {
  std::array<std::uint8_t, 32> seed{};
};

/// A new random run key (OpenSSL's RAND_bytes). Throws Error when no randomness is available.
RunKey make_run_key();
/// The run key in `path` (64 hex digits, surrounding white space allowed). Throws InvalidArgument naming the file
/// when it cannot be read or is not such a key.
RunKey load_run_key(const std::string& path);
/// Writes `key` to `path` as 64 hex digits and a newline, readable by its owner only (0600), whole or not at all
/// (a temporary file renamed). Throws IoError naming the file.
void save_run_key(const RunKey& key, const std::string& path);

/// The public key of `key`, 64 lowercase hex digits: what Admission::world_key and WorldStatus::world_key carry.
std::string world_key_of(const RunKey& key);
/// The world's proof for run `run_id` at participant `prefix` (its GUID prefix): an Ed25519 signature, 128 hex digits.
std::string prove_world(const RunKey& key, const std::string& run_id, const std::array<std::uint8_t, 12>& prefix);
/// True when `proof` is the signature under public key `world_key` (hex, as above) of run `run_id` at participant
/// `prefix`; false for anything else (malformed hex included).
bool world_proven(const std::string& world_key, const std::string& proof, const std::string& run_id,
                  const std::array<std::uint8_t, 12>& prefix);

}  // namespace marsala::protocol
