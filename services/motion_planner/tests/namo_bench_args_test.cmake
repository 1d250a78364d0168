# tamp_motion_planner_namo_bench's world arguments (issue 12): it must never run zero worlds
# silently. One mode per ctest entry:
#   missing_folder  a path that does not exist: exit 2, the message names it
#   empty_folder    a folder without worlds: exit 2, "ran nothing"
#   one_world       one shipped world, --runs 1: exit 0 and the table has that world's row
#   cmake -DMODE=... -DBENCH=<executable> -DWORLD=<world file> -DWORK=<scratch dir> -P namo_bench_args_test.cmake
cmake_minimum_required(VERSION 3.22)  # IN_LIST, and the policies of the project
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run_bench)
  execute_process(COMMAND ${BENCH} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(rc ${rc} PARENT_SCOPE)
  set(out ${out} PARENT_SCOPE)
  set(err ${err} PARENT_SCOPE)
  message(STATUS "namo_bench ${ARGN}: exit ${rc}\n${err}")
endfunction()

if(MODE STREQUAL "missing_folder")
  run_bench(--runs 1 ${WORK}/no_such_folder)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "no_such_folder: .*no such world file or folder")
    message(FATAL_ERROR "expected exit 2 naming no_such_folder, got exit ${rc}")
  endif()
elseif(MODE STREQUAL "empty_folder")
  file(MAKE_DIRECTORY ${WORK}/empty)
  file(WRITE ${WORK}/empty/notes.txt "not a world\n")
  run_bench(--runs 1 ${WORK}/empty)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "ran nothing")
    message(FATAL_ERROR "expected exit 2 saying 'ran nothing', got exit ${rc}")
  endif()
elseif(MODE STREQUAL "one_world")
  get_filename_component(stem ${WORLD} NAME_WE)
  run_bench(--runs 1 --full-runs 1 --warmup 0 --time-limit 2 --no-baselines ${WORLD})
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "expected exit 0, got ${rc}")
  endif()
  if(NOT out MATCHES "\n\\| ${stem} \\|")
    message(FATAL_ERROR "no table row for ${stem}:\n${out}")
  endif()
else()
  message(FATAL_ERROR "MODE must be missing_folder, empty_folder or one_world (got '${MODE}')")
endif()
