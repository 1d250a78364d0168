tamp_add_executable(tamp-ping SOURCES ping_main.cc DEPS tamp::dds tamp::cli11)
target_include_directories(tamp-ping PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
