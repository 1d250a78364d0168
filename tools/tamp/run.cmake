tamp_add_executable(tamp-run SOURCES run_main.cc DEPS tamp::dds tamp::process tamp::config tamp::cli11)
target_include_directories(tamp-run PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
add_dependencies(tamp-run tamp-status tamp_echo_node)
