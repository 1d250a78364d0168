tamp_add_executable(tamp-run SOURCES run_main.cc mission_run.cc launcher.cc
  DEPS tamp::dds tamp::process tamp::deploy tamp::cli11 tamp::scenario tamp::render nlohmann_json::nlohmann_json)
target_include_directories(tamp-run PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
add_dependencies(tamp-run tamp-status tamp_echo_node)
