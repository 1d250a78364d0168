# Build options. Presets in CMakePresets.json set these; defaults suit a developer build.
option(TAMP_WITH_DDS "Build the Fast DDS layer, IDL types, service nodes and executables" ON)
option(TAMP_BUILD_TESTS "Build unit and integration tests" ON)
option(TAMP_BUILD_BENCHMARKS "Build benchmark executables (not run by ctest)" ON)
option(TAMP_WERROR "Treat warnings as errors (CI)" OFF)
option(TAMP_SANITIZE "Build with AddressSanitizer + UndefinedBehaviorSanitizer" OFF)
option(TAMP_FUZZ "Build libFuzzer targets (needs clang)" OFF)
# Developer option for parallel work in one checkout: configure only these areas of common/ and
# services/ (e.g. "dds;symbolic_planner"); core and config are always built. Empty: everything.
set(TAMP_ONLY_AREAS "" CACHE STRING "Only configure these common/ and services/ areas (developers)")
function(tamp_area_enabled area out)
  if(TAMP_ONLY_AREAS STREQUAL "" OR area IN_LIST TAMP_ONLY_AREAS)
    set(${out} TRUE PARENT_SCOPE)
  else()
    set(${out} FALSE PARENT_SCOPE)
  endif()
endfunction()

find_program(TAMP_CCACHE ccache)
if(TAMP_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(CMAKE_CXX_COMPILER_LAUNCHER ${TAMP_CCACHE})
endif()

# One INTERFACE target carries the warning policy; every project target links it PRIVATE.
add_library(tamp_warnings INTERFACE)
target_compile_options(tamp_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Woverloaded-virtual
  $<$<BOOL:${TAMP_WERROR}>:-Werror>)
# GCC 12 at -O3 reports -Wrestrict inside libstdc++'s std::string (GCC bug 105329, a false
# positive in inlined char_traits::copy); keep the rest of -Wall.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(tamp_warnings INTERFACE -Wno-restrict)
endif()

if(TAMP_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
  # Eigen switches to its own aligned allocator under ASan; the executable's instances of Eigen's
  # inline functions then interpose on those of the (uninstrumented) PCL libraries, which free
  # with plain free(): a false "bad-free". glibc's and ASan's malloc are 16-byte aligned, which is
  # all Eigen needs without -march flags, so keep Eigen's allocator identical to the libraries'.
  add_compile_definitions(EIGEN_MALLOC_ALREADY_ALIGNED=1)
endif()
