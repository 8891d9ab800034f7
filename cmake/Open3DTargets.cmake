# Helpers that give every target of ours the same warnings and sanitizer flags.
# Third-party headers come in as SYSTEM includes so -Werror only judges our code.

function(open3d_set_target_flags target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Werror)
  # No fused multiply-adds the source did not ask for: the CPU reference reproduces the
  # shaders' float32 arithmetic (shaders/GaussianSplatShared.h) only when every product
  # and sum is rounded where the source says (GCC contracts by default where the target has FMA).
  target_compile_options(${target} PRIVATE -ffp-contract=off)
  if(OPEN3D_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
  if(OPEN3D_BUILD_FUZZERS)
    # Coverage instrumentation for libFuzzer in every library the harnesses link.
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endfunction()

# Test binaries and their support code: -O1 instead of the build type's -O3. Their own code
# is assertions and small loops; the libraries they test keep the build type's flags. The
# test sources are over half of the build's compile time (docs/build.md).
function(open3d_set_test_flags target)
  open3d_set_target_flags(${target})
  if(CMAKE_BUILD_TYPE STREQUAL "Release")
    target_compile_options(${target} PRIVATE -O1)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      # GCC 12 at -O1 warns of a memcpy out of bounds inside std::string's operator+ of a
      # temporary (false positives, GCC bug 105651 and its kin); -O3 does not.
      target_compile_options(${target} PRIVATE -Wno-array-bounds -Wno-stringop-overflow -Wno-restrict)
    endif()
  endif()
endfunction()

# open3d_add_library(name SOURCES ... DEPS ... SYSTEM_DEPS ... PRIVATE_DEPS ...): one library
# per layer. DEPS and SYSTEM_DEPS are PUBLIC: the library's headers include theirs, so users
# need their include paths too. PRIVATE_DEPS are used only by the library's .cpp files: users
# get the link (a static library needs it) but not the include path, so a header that starts
# including such a dependency fails to compile in the users instead of leaking it silently.
function(open3d_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;SYSTEM_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${CMAKE_SOURCE_DIR}/cpp)
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} ${ARG_SYSTEM_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  open3d_set_target_flags(${name})
endfunction()

function(open3d_add_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS})
  open3d_set_target_flags(${name})
endfunction()
