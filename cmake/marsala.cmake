# Project-wide helpers. Every library is made by marsala_library(), every unit-test folder by
# marsala_add_unit_tests(), so that warnings, the standard, the determinism flag and include roots are set once.

# marsala_warnings(TARGET): the warning set every project target compiles with.
function(marsala_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor)
endfunction()

# marsala_library(NAME SOURCES ... [PUBLIC libs...] [PRIVATE libs...])
#
# One folder = one library = one namespace = one include root. The library marsala_NAME (alias marsala::NAME) is made
# of the folder that calls this; its headers are included as "marsala/NAME/<path in the folder>". The include root
# is a directory of the build tree holding one link, marsala/NAME -> this folder, so a target sees the headers of
# exactly the libraries it links: a header of a library it does not link is "file not found", not a silent
# dependency.
function(marsala_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  set(target marsala_${name})
  if(ARG_SOURCES)
    add_library(${target} STATIC ${ARG_SOURCES})
    set(scope PUBLIC)
    target_link_libraries(${target} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
    marsala_warnings(${target})
    # Unity build (MARSALA_UNITY_BUILD, on by default): the folder's sources compile in batches of 8 per translation
    # unit, so the heavy headers (DDS, protobuf, Eigen, fmt) are parsed once per batch: a fresh build of the
    # libraries takes about half the time. Names at namespace scope of a .cpp must therefore differ across the
    # folder's files (an anonymous namespace no longer separates them).
    set_target_properties(${target} PROPERTIES UNITY_BUILD ${MARSALA_UNITY_BUILD} UNITY_BUILD_BATCH_SIZE 8)
  else()
    add_library(${target} INTERFACE)
    set(scope INTERFACE)
    target_link_libraries(${target} INTERFACE ${ARG_PUBLIC})
  endif()
  add_library(marsala::${name} ALIAS ${target})
  set(root ${PROJECT_BINARY_DIR}/include/${name})
  file(MAKE_DIRECTORY ${root}/marsala)
  file(CREATE_LINK ${CMAKE_CURRENT_SOURCE_DIR} ${root}/marsala/${name} SYMBOLIC)
  target_include_directories(${target} ${scope} ${root})
  target_compile_features(${target} ${scope} cxx_std_17)
endfunction()

# marsala_add_test(NAME SOURCE [LIBS ...] [LABELS ...]): one GoogleTest executable, registered with ctest; its cases
# carry the ctest LABELS (e.g. "fuzz", so that `ctest -L fuzz` runs them alone).
function(marsala_add_test name source)
  cmake_parse_arguments(ARG "" "" "LIBS;LABELS" ${ARGN})
  add_executable(${name} ${source})
  target_compile_features(${name} PRIVATE cxx_std_17)
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main)
  # The test's own translation unit at -O1 in optimized builds (the libraries it tests keep the build type's -O3):
  # a test file compiles in about 60 % of the time, and the code it checks is the code users run.
  target_compile_options(${name} PRIVATE $<$<NOT:$<CONFIG:Debug>>:-O1>)
  # Test helpers are included from the tests folder: "support/...", "unit/<part>/...".
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  marsala_warnings(${name})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  set(labels)
  if(ARG_LABELS)
    set(labels LABELS "${ARG_LABELS}")
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
                       PROPERTIES ENVIRONMENT "MARSALA_SOURCE_DIR=${PROJECT_SOURCE_DIR}" ${labels})
endfunction()

# marsala_add_unit_tests(PART LIBS ... [BINARIES name=target ...]): one test executable per
# tests/unit/PART/**/<unit>_test.cpp, named PART_<unit> (unit names like "format" recur in several parts). The folder
# mirrors the source folder of PART. BINARIES: executables the tests run as a user would, each passed as the
# definition name="path" (e.g. MARSALA_MONITOR_BIN=marsala-monitor) and built before the tests.
function(marsala_add_unit_tests part)
  cmake_parse_arguments(ARG "" "" "LIBS;BINARIES" ${ARGN})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tests/unit/${part}/*_test.cpp)
  foreach(source ${sources})
    get_filename_component(unit ${source} NAME_WE)
    marsala_add_test(${part}_${unit} ${source} LIBS ${ARG_LIBS})
    foreach(binary ${ARG_BINARIES})
      string(REPLACE "=" ";" pair ${binary})
      list(GET pair 0 definition)
      list(GET pair 1 executable)
      target_compile_definitions(${part}_${unit} PRIVATE ${definition}="$<TARGET_FILE:${executable}>")
      add_dependencies(${part}_${unit} ${executable})
    endforeach()
  endforeach()
endfunction()
