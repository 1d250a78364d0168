# Small helpers so every library, test and benchmark is declared the same way. Sources are listed,
# never globbed.
#
#   tamp_add_library(tamp_foo SOURCES src/a.cc ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
#       A static library with include/ as its public include directory, and an alias tamp::foo.
#   tamp_add_executable(name SOURCES ... [DEPS ...])
#   tamp_add_test(name SOURCES ... [DEPS ...] [LABELS ...] [TIMEOUT s])
#       A GoogleTest binary; each TEST becomes a ctest entry (discovered before running, not at
#       build time). Tests get TAMP_SOURCE_DIR/TAMP_BENCHMARKS_DIR/TAMP_BIN_DIR as compile definitions.
#   tamp_add_benchmark(name SOURCES ... [DEPS ...])   Google Benchmark or own bench tool; not a test.
#   tamp_add_fuzzer(name SOURCES ... [DEPS ...] [CORPUS dir])
#       libFuzzer target, only with TAMP_FUZZ (clang). With CORPUS, a ctest `<name>_libfuzzer` runs
#       it for TAMP_FUZZ_SECONDS (default 20) from that seed corpus.
#   tamp_add_fuzz_replay(name SOURCES ... [DEPS ...] CORPUS dir [MUTATIONS n])
#       The same target as a plain executable `<name>_replay` (any compiler; tests/fuzz/
#       replay_main.cc) and a ctest that replays the seed corpus plus n deterministic mutations of
#       each seed: the normal CI build exercises every fuzz target without libFuzzer.

function(tamp_add_library name)
  cmake_parse_arguments(L "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${L_SOURCES})
  target_include_directories(${name} PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
  target_link_libraries(${name} PUBLIC ${L_PUBLIC_DEPS} PRIVATE ${L_PRIVATE_DEPS} tamp_warnings)
  string(REGEX REPLACE "^tamp_" "" short ${name})
  add_library(tamp::${short} ALIAS ${name})
endfunction()

function(tamp_add_executable name)
  cmake_parse_arguments(E "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${E_SOURCES})
  target_link_libraries(${name} PRIVATE ${E_DEPS} tamp_warnings)
  tamp_sanitizer_options(${name})
endfunction()

# Sanitizer builds link this into every executable (see the file for why).
set(TAMP_ASAN_OPTIONS_SOURCE ${CMAKE_CURRENT_LIST_DIR}/asan_default_options.cc)
function(tamp_sanitizer_options target)
  if(TAMP_SANITIZE)
    target_sources(${target} PRIVATE ${TAMP_ASAN_OPTIONS_SOURCE})
  endif()
endfunction()

function(tamp_add_test name)
  if(NOT TAMP_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(T "SERIAL" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  add_executable(${name} ${T_SOURCES})
  target_link_libraries(${name} PRIVATE ${T_DEPS} GTest::gtest GTest::gmock GTest::gtest_main tamp_warnings)
  target_compile_definitions(${name} PRIVATE
    TAMP_SOURCE_DIR="${CMAKE_SOURCE_DIR}" TAMP_BENCHMARKS_DIR="${TAMP_BENCHMARKS_DIR}"
    TAMP_BIN_DIR="${CMAKE_BINARY_DIR}/bin")
  tamp_sanitizer_options(${name})
  # Paths reach tests as compile definitions (above): gtest_discover_tests splits a multi-variable
  # ENVIRONMENT property into separate arguments, so only one variable is set here.
  # SERIAL: tests that start a whole deployment (every service, a paced simulator) run alone, so
  # the machine's other tests do not starve its real-time parts.
  set(serial FALSE)
  if(T_SERIAL)
    set(serial TRUE)
  endif()
  # LABELS last: PROPERTIES is a flat key/value list, so a label list ("fault;integration") would
  # shift every pair after it (RUN_SERIAL was lost on the two-host tests, and the tests without
  # labels got one named RUN_SERIAL). Only the first label survives the discovery script's
  # expansion (an escaped ';' does not either): give the one that selects the test first.
  gtest_discover_tests(${name}
    DISCOVERY_MODE PRE_TEST
    PROPERTIES ENVIRONMENT "SKIP_DEFAULT_XML_FILE=1" TIMEOUT ${T_TIMEOUT} RUN_SERIAL ${serial} LABELS "${T_LABELS}")
endfunction()

function(tamp_add_benchmark name)
  if(NOT TAMP_BUILD_BENCHMARKS)
    return()
  endif()
  cmake_parse_arguments(B "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${B_SOURCES})
  target_link_libraries(${name} PRIVATE ${B_DEPS} tamp_warnings)
  target_compile_definitions(${name} PRIVATE
    TAMP_SOURCE_DIR="${CMAKE_SOURCE_DIR}" TAMP_BENCHMARKS_DIR="${TAMP_BENCHMARKS_DIR}")
endfunction()

# Fuzz targets share tests/fuzz/fuzz_input.h (bytes -> values).
set(TAMP_FUZZ_INCLUDE_DIR "${CMAKE_CURRENT_LIST_DIR}/../tests/fuzz")
function(tamp_add_fuzzer name)
  if(NOT TAMP_FUZZ)
    return()
  endif()
  cmake_parse_arguments(F "" "CORPUS" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${F_SOURCES})
  target_compile_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_options(${name} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_libraries(${name} PRIVATE ${F_DEPS})
  target_include_directories(${name} PRIVATE ${TAMP_FUZZ_INCLUDE_DIR})
  if(F_CORPUS)
    if(NOT DEFINED TAMP_FUZZ_SECONDS)
      set(TAMP_FUZZ_SECONDS 20)
    endif()
    # New inputs go to the build tree's corpus (first directory); the repository's seeds are read.
    set(work ${CMAKE_BINARY_DIR}/fuzz-corpus/${name})
    file(MAKE_DIRECTORY ${work})
    add_test(NAME ${name}_libfuzzer
      COMMAND ${name} -max_total_time=${TAMP_FUZZ_SECONDS} -timeout=10 -rss_limit_mb=2048 ${work} ${F_CORPUS})
    set_tests_properties(${name}_libfuzzer PROPERTIES LABELS fuzz TIMEOUT 300
      ENVIRONMENT "SKIP_DEFAULT_XML_FILE=1")
  endif()
endfunction()

function(tamp_add_fuzz_replay name)
  if(NOT TAMP_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(R "" "CORPUS;MUTATIONS" "SOURCES;DEPS" ${ARGN})
  if(NOT R_MUTATIONS)
    set(R_MUTATIONS 200)
  endif()
  add_executable(${name}_replay ${R_SOURCES} ${TAMP_FUZZ_INCLUDE_DIR}/replay_main.cc)
  target_compile_definitions(${name}_replay PRIVATE TAMP_FUZZ_REPLAY=1)
  target_link_libraries(${name}_replay PRIVATE ${R_DEPS} tamp_warnings)
  target_include_directories(${name}_replay PRIVATE ${TAMP_FUZZ_INCLUDE_DIR})
  tamp_sanitizer_options(${name}_replay)
  add_test(NAME ${name}_replay COMMAND ${name}_replay --mutations ${R_MUTATIONS} ${R_CORPUS})
  set_tests_properties(${name}_replay PROPERTIES LABELS fuzz TIMEOUT 120 ENVIRONMENT "SKIP_DEFAULT_XML_FILE=1")
endfunction()
