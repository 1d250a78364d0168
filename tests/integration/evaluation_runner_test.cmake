# The evaluation runner (tools/evaluation/evaluate.py) run as a user runs it, then what it wrote is
# checked. One mode per ctest entry:
#   quick         --quick on namo_corridor_short: exit 0, the CSV row and the table row say succeeded
#   empty_folder  a folder without scenarios or worlds: non-zero, "ran nothing"
#   unknown_file  a file that is neither kind: non-zero, the message names the file
#   folder_list   --list on a folder built here: scenarios and world JSONs are found recursively,
#                 a bare SVG is a world, an SVG that a JSON beside it names as geometry is not,
#                 and other files are reported as skipped
#   cmake -DMODE=... -DSOURCE=<repo> -DBUILD=<build dir> -DWORK=<scratch dir> -P evaluation_runner_test.cmake
cmake_minimum_required(VERSION 3.22)  # IN_LIST, and the policies of the project
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(runner ${SOURCE}/tools/evaluation/evaluate.py)

function(run_runner)
  execute_process(COMMAND ${runner} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(rc ${rc} PARENT_SCOPE)
  set(out ${out} PARENT_SCOPE)
  set(err ${err} PARENT_SCOPE)
  message(STATUS "evaluate.py ${ARGN}: exit ${rc}\n${out}${err}")
endfunction()

if(MODE STREQUAL "quick")
  run_runner(--quick --no-plot --build ${BUILD} --out ${WORK}/quick --mission-timeout 120 --domain-base 120
             ${SOURCE}/config/scenarios/namo_corridor_short.yaml)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "expected exit 0, got ${rc}")
  endif()
  file(READ ${WORK}/quick.csv csv)
  if(NOT csv MATCHES "\nnamo_corridor_short,[^,\n]*,effort,1,0,succeeded,")
    message(FATAL_ERROR "no succeeded effort seed-1 row for namo_corridor_short in quick.csv:\n${csv}")
  endif()
  file(READ ${WORK}/quick.md md)
  if(NOT md MATCHES "\\| namo_corridor_short \\| effort \\| 1/1 \\|")
    message(FATAL_ERROR "quick.md has no aggregate row 'namo_corridor_short | effort | 1/1':\n${md}")
  endif()
elseif(MODE STREQUAL "empty_folder")
  file(MAKE_DIRECTORY ${WORK}/empty)
  run_runner(--build ${BUILD} --out ${WORK}/empty_out ${WORK}/empty)
  if(rc EQUAL 0 OR NOT err MATCHES "ran nothing")
    message(FATAL_ERROR "expected a non-zero exit saying 'ran nothing', got exit ${rc}")
  endif()
  if(EXISTS ${WORK}/empty_out.md)
    message(FATAL_ERROR "wrote a table although it ran nothing")
  endif()
elseif(MODE STREQUAL "unknown_file")
  run_runner(--build ${BUILD} --out ${WORK}/unknown_out ${SOURCE}/README.md)
  if(rc EQUAL 0 OR NOT err MATCHES "README.md: neither a scenario")
    message(FATAL_ERROR "expected a non-zero exit naming README.md, got exit ${rc}")
  endif()
elseif(MODE STREQUAL "folder_list")
  set(namo ${SOURCE}/tests/data/benchmarks/namo)
  file(MAKE_DIRECTORY ${WORK}/mix/a/b ${WORK}/mix/c)
  file(COPY ${namo}/s-namo_cases/01_basic/01_basic.json ${namo}/s-namo_cases/01_basic/01_basic.svg
       DESTINATION ${WORK}/mix/a/b)
  file(COPY ${namo}/moghaddam_planning_2016_benchmark/moghaddam_planning_2016_benchmark_13.svg
       ${SOURCE}/config/scenarios/namo_corridor_short.yaml DESTINATION ${WORK}/mix/c)
  file(WRITE ${WORK}/mix/notes.txt "not a scenario\n")
  run_runner(--list ${WORK}/mix)
  string(REPLACE "\n" ";" listed "${out}")
  set(expected "world\t01_basic\t${WORK}/mix/a/b/01_basic.json"
               "scenario\tnamo_corridor_short\t${WORK}/mix/c/namo_corridor_short.yaml"
               "world\tmoghaddam_planning_2016_benchmark_13\t${WORK}/mix/c/moghaddam_planning_2016_benchmark_13.svg")
  foreach(line IN LISTS expected)
    if(NOT line IN_LIST listed)
      message(FATAL_ERROR "--list did not print '${line}':\n${out}")
    endif()
  endforeach()
  list(LENGTH listed n)
  if(NOT rc EQUAL 0 OR NOT n EQUAL 4)  # 3 lines and the empty string after the last newline
    message(FATAL_ERROR "expected exit 0 and exactly 3 cases (01_basic.svg is geometry), got exit ${rc}:\n${out}")
  endif()
  if(NOT err MATCHES "skipped ${WORK}/mix/notes.txt")
    message(FATAL_ERROR "notes.txt not reported as skipped:\n${err}")
  endif()
else()
  message(FATAL_ERROR "MODE must be quick, empty_folder, unknown_file or folder_list (got '${MODE}')")
endif()
