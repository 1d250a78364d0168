# `tamp launch DEPLOYMENT --host NAME`: one host's services, supervised (issue 13).
tamp_add_executable(tamp-launch SOURCES launch_main.cc launcher.cc
  DEPS tamp::dds tamp::process tamp::deploy tamp::cli11 nlohmann_json::nlohmann_json)
target_include_directories(tamp-launch PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
add_dependencies(tamp-launch tamp-status tamp_echo_node)
