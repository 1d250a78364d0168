# `tamp plan DOMAIN PROBLEM`: the symbolic planner as a lean executable (issue 3). Start-up time
# counts in the IPC benchmark: link only the planner library, and drop unused shared libraries
# (spdlog, fmt, ...) that tamp::core would otherwise add as NEEDED entries.
tamp_add_executable(tamp-plan SOURCES plan_main.cc DEPS tamp::symbolic_planner tamp::cli11)
target_include_directories(tamp-plan PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
target_link_options(tamp-plan PRIVATE -Wl,--as-needed
  $<$<CXX_COMPILER_ID:GNU>:-static-libstdc++ -static-libgcc>)
