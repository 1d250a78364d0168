# `tamp render SCENARIO -o out.png|out.svg`: a top-down picture of a scenario (or a NAMO world).
tamp_add_executable(tamp-render SOURCES render_main.cc DEPS tamp::scenario tamp::render tamp::cli11)
target_include_directories(tamp-render PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
