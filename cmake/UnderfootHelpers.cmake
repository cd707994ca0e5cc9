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
  gtest_discover_tests(${target} PROPERTIES LABELS ${label} TIMEOUT ${ARG_TIMEOUT}
                       DISCOVERY_TIMEOUT 60)
endfunction()
