# Build options shared by every target. Our own targets opt in to the strict
# warnings through adit_target_defaults(); sanitizers apply to everything.

option(ADIT_BUILD_TESTS "Build the GoogleTest suite" ON)
option(ADIT_BUILD_BENCHMARKS "Build the Google Benchmark programs" ON)
option(ADIT_SANITIZE_ADDRESS "Build everything with AddressSanitizer + UndefinedBehaviorSanitizer" OFF)
option(ADIT_SANITIZE_THREAD "Build everything with ThreadSanitizer" OFF)
option(ADIT_USE_CCACHE "Use ccache when it is installed" ON)
option(ADIT_BUILD_FUZZERS "Build libFuzzer targets (needs clang)" OFF)

if(ADIT_SANITIZE_ADDRESS AND ADIT_SANITIZE_THREAD)
  message(FATAL_ERROR "ADIT_SANITIZE_ADDRESS and ADIT_SANITIZE_THREAD cannot be combined")
endif()

if(ADIT_USE_CCACHE)
  find_program(CCACHE_PROGRAM ccache)
  if(CCACHE_PROGRAM)
    set(CMAKE_C_COMPILER_LAUNCHER ${CCACHE_PROGRAM})
    # The tests' precompiled header is cached, and so are the files that use
    # it, only with these two sloppinesses (ccache's manual, "Precompiled
    # headers"): the header's own macros are not hashed, nor __TIME__.
    set(CMAKE_CXX_COMPILER_LAUNCHER ${CMAKE_COMMAND} -E env CCACHE_SLOPPINESS=pch_defines,time_macros ${CCACHE_PROGRAM})
  endif()
endif()

if(ADIT_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "ADIT_BUILD_FUZZERS needs clang: CC=clang CXX=clang++ cmake ...")
  endif()
  # Every library is instrumented for coverage; only the fuzz executables link
  # libFuzzer's main (adit_fuzzer in tests/CMakeLists.txt).
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

if(ADIT_SANITIZE_ADDRESS)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
if(ADIT_SANITIZE_THREAD)
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()

# Strict warnings for the project's own code only: third-party headers are
# included as SYSTEM so they cannot fail our build.
function(adit_target_defaults target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Werror)
endfunction()

# A library per folder: adit_library(NAME adit_x SOURCES ... DEPS ...)
# A folder with no sources yet is an INTERFACE library (headers only).
function(adit_library)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  if(ARG_SOURCES)
    add_library(${ARG_NAME} STATIC ${ARG_SOURCES})
    target_include_directories(${ARG_NAME} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
    target_link_libraries(${ARG_NAME} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    adit_target_defaults(${ARG_NAME})
  else()
    add_library(${ARG_NAME} INTERFACE)
    target_include_directories(${ARG_NAME} INTERFACE ${CMAKE_CURRENT_SOURCE_DIR}/include)
    target_link_libraries(${ARG_NAME} INTERFACE ${ARG_PUBLIC_DEPS})
  endif()
endfunction()

# An executable of ours: adit_executable(NAME x SOURCES ... DEPS ...)
function(adit_executable)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;DEPS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS})
  adit_target_defaults(${ARG_NAME})
endfunction()

# LCM's C++ header (lcm-cpp-impl.hpp) calls its subscription objects through a
# C callback in a way UBSan's vptr check rejects; the check is dropped for the
# files that include that header, and only for them:
#   adit_without_vptr_check(file.cpp ...)
function(adit_without_vptr_check)
  if(ADIT_SANITIZE_ADDRESS)
    set_source_files_properties(${ARGN} PROPERTIES COMPILE_OPTIONS "-fno-sanitize=vptr")
  endif()
endfunction()
