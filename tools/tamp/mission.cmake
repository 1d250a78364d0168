tamp_add_executable(tamp-mission SOURCES mission_main.cc mission_run.cc join_run.cc
  DEPS tamp::dds tamp::deploy tamp::cli11 tamp::scenario tamp::render nlohmann_json::nlohmann_json)
target_include_directories(tamp-mission PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
