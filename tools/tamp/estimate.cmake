# `tamp estimate show|fit|predict`: inspect, refit or query an effort estimator store (issue 5).
tamp_add_executable(tamp-estimate SOURCES estimate_main.cc
  DEPS tamp::effort_estimator tamp::cli11 nlohmann_json::nlohmann_json)
target_include_directories(tamp-estimate PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
