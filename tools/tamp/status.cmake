tamp_add_executable(tamp-status SOURCES status_main.cc DEPS tamp::dds tamp::deploy tamp::cli11 nlohmann_json::nlohmann_json)
target_include_directories(tamp-status PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
