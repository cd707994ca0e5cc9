# Helpers shared by every target of the project.

# Warnings and (optionally) sanitizers for one of our own targets.
function(underfoot_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wconversion -Wno-sign-conversion)
  if(UNDERFOOT_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
  if(UNDERFOOT_FUZZ) # coverage for libFuzzer in every target; fuzz targets link -fsanitize=fuzzer
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endfunction()

# Precompiled third-party headers for a target of many sources: each of its translation units
# otherwise parses them again (GoogleTest + GoogleMock ~3 s, CLI11 ~4 s of every file's compile
# here). Only system headers whose meaning does not depend on our code go in; the build is the same
# without it (-DUNDERFOOT_PCH=OFF).
# GCC 12 with a precompiled header reports libstdc++'s own std::string copies (char_traits.h,
# inlined into string concatenations) as -Warray-bounds, and with that off as
# -Wstringop-overflow, which the same file without the precompiled header does not
# (tests/soundscapes/test_renderer.cpp: 4 warnings with, 0 without, also 0 with the same headers
# -include'd uncompiled): a false positive of the compiler's precompiled-header path, so these two
# warnings are off where a precompiled header is used with GCC < 13. The sanitizer build checks
# these targets' bounds at run time.
function(underfoot_precompile target)
  if(UNDERFOOT_PCH)
    target_precompile_headers(${target} PRIVATE ${ARGN})
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
      target_compile_options(${target} PRIVATE -Wno-array-bounds -Wno-stringop-overflow)
    endif()
  endif()
endfunction()

# A library made of every .cpp below one folder (each part of the project is one library).
function(underfoot_add_library target folder)
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${folder}/*.cpp)
  file(GLOB_RECURSE headers CONFIGURE_DEPENDS ${folder}/*.h)
  add_library(${target} STATIC ${sources} ${headers})
  target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR})
  underfoot_target_defaults(${target})
endfunction()

# One GoogleTest executable per test folder, every test labelled with its part so that
# `ctest -L part` runs that part alone.
function(underfoot_add_gtest target label)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;LIBS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  add_executable(${target} ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main GTest::gmock)
  target_compile_definitions(${target} PRIVATE UNDERFOOT_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data"
                                               UNDERFOOT_BINARY_DIR="${PROJECT_BINARY_DIR}")
  underfoot_target_defaults(${target})
  list(LENGTH ARG_SOURCES source_count)
  if(source_count GREATER 2)
    underfoot_precompile(${target} <gtest/gtest.h> <gmock/gmock.h> <string> <vector>)
  endif()
  gtest_discover_tests(${target} PROPERTIES LABELS ${label} TIMEOUT ${ARG_TIMEOUT}
                       DISCOVERY_TIMEOUT 60)
endfunction()
