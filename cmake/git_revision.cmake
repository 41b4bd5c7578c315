# Script mode (cmake -P), run at every build by the target marsala_revision (common/cli/CMakeLists.txt):
#   cmake -DSOURCE_DIR=<tree> -DVERSION=<project version> -DOUT=<file.cpp> -P git_revision.cmake
# Writes OUT, a source file of the build tree defining the project version and the git revision of SOURCE_DIR's
# checkout (12 hex digits, "-dirty" when tracked files differ from it; "unknown" outside a git checkout or without
# git). OUT is rewritten only when its text changes, so an unchanged revision rebuilds nothing.
set(revision "unknown")
find_program(GIT git)
if(GIT)
  execute_process(COMMAND ${GIT} -C ${SOURCE_DIR} rev-parse --short=12 HEAD
                  OUTPUT_VARIABLE head RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(rc EQUAL 0 AND NOT head STREQUAL "")
    set(revision ${head})
    execute_process(COMMAND ${GIT} -C ${SOURCE_DIR} status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE changes RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(rc EQUAL 0 AND NOT changes STREQUAL "")
      set(revision "${revision}-dirty")
    endif()
  endif()
endif()
set(text "// Written by cmake/git_revision.cmake at build time; not part of the source tree.
namespace marsala::cli::detail {
extern const char* const kProjectVersion;
extern const char* const kGitRevision;
const char* const kProjectVersion = \"${VERSION}\";
const char* const kGitRevision = \"${revision}\";
}  // namespace marsala::cli::detail
")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
else()
  set(old "")
endif()
if(NOT old STREQUAL text)
  file(WRITE ${OUT} "${text}")
endif()
