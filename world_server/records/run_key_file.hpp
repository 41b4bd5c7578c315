#pragma once
// The run key in the run folder (docs/runtime.md#who-wrote-it): a fresh run keeps its key in OUT/run.key (0600), so
// that the world resumed from that folder proves itself with the same key and its agents and monitors, which pinned
// the key, believe it; a stranger on the domain, without the folder, cannot.

#include <string>

#include "marsala/protocol/world_proof.hpp"

namespace marsala::world_server {

/// The run key's file in run folder `dir`.
std::string run_key_path(const std::string& dir);

/// The key a run proves itself with. `given`: a --run-key file (read; InvalidArgument naming it when bad), else a
/// fresh run makes one, and a resumed run reads `dir`'s run.key (a folder without one, written before run keys:
/// a new key, logged). A fresh run saves the key in `dir`/run.key (IoError when it cannot).
protocol::RunKey settle_run_key(const std::string& given, const std::string& dir, bool resumed);

}  // namespace marsala::world_server
