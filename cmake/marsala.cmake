# Project-wide helpers: warnings per target, one-line test registration.

# marsala_warnings(TARGET): the warning set every project target compiles with.
function(marsala_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor)
endfunction()

# marsala_add_test(NAME SOURCE [LIBS ...]): one GoogleTest executable, registered with ctest.
function(marsala_add_test name source)
  cmake_parse_arguments(ARG "" "" "LIBS" ${ARGN})
  add_executable(${name} ${source})
  target_compile_features(${name} PRIVATE cxx_std_17)
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main)
  marsala_warnings(${name})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
                       PROPERTIES ENVIRONMENT "MARSALA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
endfunction()
