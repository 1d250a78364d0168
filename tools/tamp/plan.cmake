# `tamp plan DOMAIN PROBLEM`: the symbolic planner as a lean executable (issue 3). Start-up time
# counts in the IPC benchmark: link only the planner library (tamp::symbolic_planner needs only
# tamp::core_base, no spdlog or fmt); see below for the static link.
tamp_add_executable(tamp-plan SOURCES plan_main.cc DEPS tamp::symbolic_planner tamp::cli11)
target_include_directories(tamp-plan PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
# Linked statically, as a position-independent executable (issue 14, thirteenth round): a run on a
# small task (10-15 ms) is 0.7-2.3 ms faster without the dynamic loader and the shared libc and libm
# (docs/benchmarks.md). The planner links no third-party library (tamp::core_base), so only the C
# and C++ runtimes' archives are needed; where they are missing (no libc.a), or under the
# sanitizers (their runtimes are shared objects), the executable stays dynamic.
# TAMP_PLAN_STATIC=OFF keeps it dynamic.
option(TAMP_PLAN_STATIC "Link tamp-plan statically (static-pie) where the toolchain can" ON)
set(tamp_plan_static FALSE)
if(TAMP_PLAN_STATIC AND NOT TAMP_SANITIZE AND NOT TAMP_FUZZ)
  include(CheckCXXSourceCompiles)
  set(CMAKE_REQUIRED_LINK_OPTIONS -static-pie)
  check_cxx_source_compiles("#include <string>
    int main(int argc, char**) { return static_cast<int>(std::to_string(argc).size()); }"
    TAMP_HAVE_STATIC_PIE)
  unset(CMAKE_REQUIRED_LINK_OPTIONS)
  if(TAMP_HAVE_STATIC_PIE)
    set(tamp_plan_static TRUE)
  endif()
endif()
if(tamp_plan_static)
  # Alone: g++ 12 with -static-libgcc as well links a dynamic executable that crashes at start.
  target_link_options(tamp-plan PRIVATE -static-pie)
else()
  target_link_options(tamp-plan PRIVATE -Wl,--as-needed
    $<$<CXX_COMPILER_ID:GNU>:-static-libstdc++ -static-libgcc>)
endif()
# The CLI test checks that the executable is static exactly when this says so.
if(TARGET tamp_symbolic_planner_tests)
  target_compile_definitions(tamp_symbolic_planner_tests PRIVATE
    TAMP_PLAN_STATIC_EXPECTED=$<BOOL:${tamp_plan_static}>)
endif()
