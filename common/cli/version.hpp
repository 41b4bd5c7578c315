#pragma once
// What `--version` prints on every MARSala program: the project version (CMakeLists.txt) and the git revision of the
// source tree it was built from, taken at build time (cmake/git_revision.cmake), e.g.
//   marsala-world 0.1.0 (git 4a89846abcd1)
// "-dirty" follows the revision when tracked files differed from it; "unknown" when built outside a git checkout.

#include <string>

namespace marsala::cli {

/// The project version, e.g. "0.1.0".
const char* project_version();
/// The git revision the program was built from: 12 hex digits, maybe "-dirty", or "unknown".
const char* git_revision();
/// "<program> <version> (git <revision>)".
std::string version_text(const std::string& program);

}  // namespace marsala::cli
