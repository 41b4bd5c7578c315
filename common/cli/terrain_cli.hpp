#pragma once
// The marsala-terrain command line as a callable function, so tests can drive it in-process.

#include <iosfwd>

namespace marsala::cli {

/// Runs marsala-terrain with argv; returns the exit code (0 ok, 1 data error, 2 usage error).
/// Errors go to `err` as one line "marsala-terrain: <reason>".
int run_terrain_cli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace marsala::cli
