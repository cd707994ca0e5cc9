# Helpers shared by every target of the project.

# Warnings and (optionally) sanitizers for one of our own targets.
function(underfoot_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wconversion -Wno-sign-conversion)
  if(UNDERFOOT_UNITY AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # A unity batch #includes its .cpp files, and GCC then warns about every test fixture in an
    # anonymous namespace ("has a base whose type uses the anonymous namespace"): each file is
    # still its own part of the batch, so the warning says nothing there.
    target_compile_options(${target} PRIVATE -Wno-subobject-linkage)
  endif()
  if(UNDERFOOT_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
  if(UNDERFOOT_FUZZ) # coverage for libFuzzer in every target; fuzz targets link -fsanitize=fuzzer
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endfunction()

# Precompiled third-party headers for a target of many sources that each parse them again
# (`underfoot`: CLI11 and fmt in every cmd_*.cpp, 17.2 -> 13.5 s for cmd_stats.cpp here). The
# build is the same without it (-DUNDERFOOT_PCH=OFF). Not used for the test executables: there
# GoogleTest's precompiled header saved no measurable time (per file within the noise, a 10-12 s
# header per executable) and GCC 12 reported false -Warray-bounds / -Wstringop-overflow in
# libstdc++'s string copies through it (tests/soundscapes/test_renderer.cpp: 4 with, 0 without).
function(underfoot_precompile target)
  if(UNDERFOOT_PCH)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()

# Sources compiled on their own in a unity build (UNDERFOOT_UNITY): their file-local helpers or
# constants share a name with a neighbour's. Call it in the folder that creates the target.
function(underfoot_no_unity)
  set_source_files_properties(${ARGN} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
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
  # Tests (only they) may name files of the source tree; the programs find their data through
  # base/DataDir.h.
  target_compile_definitions(${target} PRIVATE UNDERFOOT_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data"
                                               UNDERFOOT_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                               UNDERFOOT_BINARY_DIR="${PROJECT_BINARY_DIR}")
  underfoot_target_defaults(${target})
  gtest_discover_tests(${target} PROPERTIES LABELS ${label} TIMEOUT ${ARG_TIMEOUT}
                       DISCOVERY_TIMEOUT 60)
endfunction()
