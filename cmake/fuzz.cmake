# libFuzzer targets for swirl's readers of untrusted input (issue 5, "Hostile
# input"). Built with clang from the repository's sources directly, separately
# from the main (g++) build, by the project in tests/fuzz/:
#
#   cmake -S tests/fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++
#   cmake --build build-fuzz
#
# or simply .ci/fuzz.sh, which also runs every target on a copy of its corpus.
#
# Every tests/fuzz/NAME_fuzz.cpp becomes the executable NAME_fuzz. Its seed
# corpus is tests/fuzz/corpus/NAME/, its dictionary (optional)
# tests/fuzz/NAME.dict, and its kept crashes tests/fuzz/regressions/NAME/. The
# swirl modules it needs are named in the source, in one comment line:
#
#   // fuzz-modules: scene gravity
#
# Each module src/MODULE/*.cpp is compiled once into a static library with
# -fsanitize=fuzzer-no-link,address,undefined, so adding a target is one file.
include_guard(GLOBAL)

get_filename_component(SWIRL_ROOT "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)

if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "swirl fuzz targets need clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++ "
                      "(found ${CMAKE_CXX_COMPILER_ID} ${CMAKE_CXX_COMPILER})")
endif()

set(CMAKE_CXX_STANDARD 20)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS OFF)
if(NOT CMAKE_BUILD_TYPE)
  # The flags below set the optimisation; keep CMake from adding -O3 -DNDEBUG.
  set(CMAKE_BUILD_TYPE Fuzz)
endif()

set(SWIRL_FUZZ_SANITIZERS "address,undefined" CACHE STRING "Sanitizers besides libFuzzer's own coverage")
option(SWIRL_FUZZ_TOML_HEADER_ONLY
  "Compile toml++ header-only into the fuzz targets, so its parser is instrumented too (Debian ships it compiled)" ON)

find_package(OpenMP REQUIRED COMPONENTS CXX)  # clang: libomp (Debian libomp-dev)
find_package(fmt REQUIRED)
find_package(tomlplusplus REQUIRED)

# The generated header the main build writes; nothing in src/ needs more than this.
set(PROJECT_VERSION "fuzz")
set(SWIRL_GIT_REVISION "fuzz")
configure_file(${SWIRL_ROOT}/cmake/config.hpp.in ${CMAKE_BINARY_DIR}/generated/swirl/config.hpp @ONLY)

# Everything compiled here carries coverage instrumentation and the sanitizers;
# UBSan aborts, so that libFuzzer records the input.
add_library(swirl_fuzz_flags INTERFACE)
target_compile_options(swirl_fuzz_flags INTERFACE
  -g -O1 -fno-omit-frame-pointer -Wno-pass-failed
  -fsanitize=fuzzer-no-link,${SWIRL_FUZZ_SANITIZERS} -fno-sanitize-recover=all
  # Known, harmless UB in a dependency; see the file.
  -fsanitize-ignorelist=${SWIRL_ROOT}/tests/fuzz/ubsan_ignorelist.txt)
target_link_options(swirl_fuzz_flags INTERFACE -fsanitize=${SWIRL_FUZZ_SANITIZERS})
target_include_directories(swirl_fuzz_flags INTERFACE ${SWIRL_ROOT}/include ${CMAKE_BINARY_DIR}/generated)
target_link_libraries(swirl_fuzz_flags INTERFACE OpenMP::OpenMP_CXX fmt::fmt)
if(SWIRL_FUZZ_TOML_HEADER_ONLY)
  # The parser is most of what the scene fuzzer exercises; without coverage
  # feedback from it, libFuzzer rarely gets past TOML syntax.
  get_target_property(toml_includes tomlplusplus::tomlplusplus INTERFACE_INCLUDE_DIRECTORIES)
  target_include_directories(swirl_fuzz_flags SYSTEM INTERFACE ${toml_includes})
  target_compile_definitions(swirl_fuzz_flags INTERFACE TOML_HEADER_ONLY=1)
  # toml++'s asserts off, as in Debian's build of it; see the file.
  target_compile_options(swirl_fuzz_flags INTERFACE -include ${SWIRL_ROOT}/tests/fuzz/toml_config.hpp)
else()
  target_link_libraries(swirl_fuzz_flags INTERFACE tomlplusplus::tomlplusplus)
endif()

# One static library per swirl module, made on first use.
function(swirl_fuzz_module module out_target)
  set(target swirl_fuzz_${module})
  if(NOT TARGET ${target})
    file(GLOB sources CONFIGURE_DEPENDS ${SWIRL_ROOT}/src/${module}/*.cpp)
    if(NOT sources)
      message(FATAL_ERROR "fuzz: no sources in src/${module}/ (named in a fuzz-modules line)")
    endif()
    add_library(${target} STATIC ${sources})
    target_link_libraries(${target} PUBLIC swirl_fuzz_flags)
    # Sources no fuzz target runs, kept at -O0: clang 14 with ASan+UBSan at
    # -O1 spent 45 minutes of a CI run on fmm.cpp alone (its expansion loops);
    # at -O0 it takes about one. The scene fuzzer only validates method "fmm".
    foreach(cold_source IN ITEMS gravity/fmm.cpp)
      if(EXISTS ${SWIRL_ROOT}/src/${cold_source} AND cold_source MATCHES "^${module}/")
        set_source_files_properties(${SWIRL_ROOT}/src/${cold_source} TARGET_DIRECTORY ${target}
                                    PROPERTIES COMPILE_OPTIONS -O0)
      endif()
    endforeach()
    if(module STREQUAL "io")  # the HDF5 snapshots, the mesh files
      include(${SWIRL_ROOT}/cmake/hdf5.cmake)
      include(${SWIRL_ROOT}/cmake/assimp.cmake)
      target_link_libraries(${target} PUBLIC swirl_hdf5 assimp::assimp)
    endif()
  endif()
  set(${out_target} ${target} PARENT_SCOPE)
endfunction()

file(GLOB SWIRL_FUZZ_SOURCES CONFIGURE_DEPENDS ${SWIRL_ROOT}/tests/fuzz/*_fuzz.cpp)
set(SWIRL_FUZZ_TARGETS "")
foreach(source IN LISTS SWIRL_FUZZ_SOURCES)
  get_filename_component(name ${source} NAME_WE)
  file(STRINGS ${source} modules_line REGEX "^// fuzz-modules:" LIMIT_COUNT 1)
  string(REGEX REPLACE "^// fuzz-modules:[ \t]*" "" modules "${modules_line}")
  string(STRIP "${modules}" modules)
  string(REGEX REPLACE "[ \t]+" ";" modules "${modules}")
  # core under every module (ParticleSet's compiled float and double copies).
  list(APPEND modules core)
  list(REMOVE_DUPLICATES modules)
  set(libraries "")
  foreach(module IN LISTS modules)
    swirl_fuzz_module(${module} lib)
    list(APPEND libraries ${lib})
  endforeach()
  add_executable(${name} ${source})
  # The modules depend on each other (scene on gravity); a rescanned group
  # makes the order of the fuzz-modules line irrelevant.
  if(libraries)
    list(JOIN libraries "," group)
    target_link_libraries(${name} PRIVATE "$<LINK_GROUP:RESCAN,${group}>")
  endif()
  target_link_libraries(${name} PRIVATE swirl_fuzz_flags)
  target_include_directories(${name} PRIVATE ${SWIRL_ROOT}/tests)
  target_link_options(${name} PRIVATE -fsanitize=fuzzer)
  list(APPEND SWIRL_FUZZ_TARGETS ${name})
endforeach()
message(STATUS "swirl fuzz targets: ${SWIRL_FUZZ_TARGETS}")
