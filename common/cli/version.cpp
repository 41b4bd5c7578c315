#include "marsala/cli/version.hpp"

#include <fmt/format.h>

namespace marsala::cli {
namespace detail {
// Defined in the build tree's revision.cpp (cmake/git_revision.cmake).
extern const char* const kProjectVersion;
extern const char* const kGitRevision;
}  // namespace detail

const char* project_version() { return detail::kProjectVersion; }

const char* git_revision() { return detail::kGitRevision; }

std::string version_text(const std::string& program) {
  return fmt::format("{} {} (git {})", program, project_version(), git_revision());
}

}  // namespace marsala::cli
