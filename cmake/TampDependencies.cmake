# Every third-party find_package lives here, once. Versions are Debian 12's (see docs/dependencies.md).
# Imported targets without namespaces are wrapped into tamp::<name> INTERFACE targets whose include
# directories are SYSTEM, so -Wpedantic noise from third-party headers stays out of our builds.

find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(spdlog REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3 REQUIRED)

function(tamp_wrap_dependency name)
  cmake_parse_arguments(W "" "" "INCLUDES;LIBS" ${ARGN})
  add_library(tamp_dep_${name} INTERFACE)
  if(W_INCLUDES)
    target_include_directories(tamp_dep_${name} SYSTEM INTERFACE ${W_INCLUDES})
  endif()
  target_link_libraries(tamp_dep_${name} INTERFACE ${W_LIBS})
  add_library(tamp::${name} ALIAS tamp_dep_${name})
endfunction()

# yaml-cpp 0.7 exports a plain `yaml-cpp` target.
tamp_wrap_dependency(yaml LIBS yaml-cpp)

# Geometry, planning, estimation, perception. Found always: the algorithm libraries need them
# whether or not DDS is built.
find_package(orocos_kdl REQUIRED)
tamp_wrap_dependency(kdl INCLUDES ${orocos_kdl_INCLUDE_DIRS} LIBS ${orocos_kdl_LIBRARIES})
find_package(ompl 1.5 REQUIRED)          # lower-case config file; no imported target in 1.5
tamp_wrap_dependency(ompl INCLUDES ${OMPL_INCLUDE_DIRS} LIBS ${OMPL_LIBRARIES})
# KDL loaded before OMPL by every binary that links OMPL: both export the weak
# Eigen::JacobiSVD<MatrixXd>::allocate, the dynamic linker binds KDL's calls to the first library
# loaded, and with OMPL's copy KDL's LMA IK aborts on an Eigen assertion (docs/architecture.md,
# section 8). Link options come before every library on the command line, so this -l is the first
# NEEDED entry; CMake's ordering of the libraries themselves puts OMPL first in some binaries.
find_library(TAMP_KDL_LIBRARY NAMES orocos-kdl REQUIRED)
target_link_options(tamp_dep_ompl INTERFACE "LINKER:--push-state,--no-as-needed" "${TAMP_KDL_LIBRARY}"
                    "LINKER:--pop-state")
find_package(fcl 0.7 REQUIRED)           # target `fcl`, brings ccd and octomap
tamp_wrap_dependency(fcl LIBS fcl)
find_package(octomap 1.9 REQUIRED)
tamp_wrap_dependency(octomap INCLUDES ${OCTOMAP_INCLUDE_DIRS} LIBS octomap)
find_package(Ceres 2.1 REQUIRED)         # Debian ships libceres.a behind Ceres::ceres
tamp_wrap_dependency(ceres LIBS Ceres::ceres)
set(CMAKE_DISABLE_FIND_PACKAGE_VTK TRUE) # PCL's optional VTK breaks a CXX-only project (VTK::mpi)
find_package(PCL 1.13 QUIET REQUIRED COMPONENTS common filters segmentation sample_consensus kdtree search)
tamp_wrap_dependency(pcl INCLUDES ${PCL_INCLUDE_DIRS}
  LIBS pcl_common pcl_filters pcl_segmentation pcl_sample_consensus pcl_kdtree pcl_search)
find_package(urdfdom REQUIRED)           # no version file on Debian
tamp_wrap_dependency(urdfdom LIBS urdfdom::urdfdom_model)
find_package(PkgConfig REQUIRED)
pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo)
tamp_wrap_dependency(cairo LIBS PkgConfig::CAIRO)
find_package(SQLite3 REQUIRED)
tamp_wrap_dependency(sqlite LIBS SQLite::SQLite3)
find_package(CLI11 REQUIRED)
tamp_wrap_dependency(cli11 LIBS CLI11::CLI11)
# Optional: libnetfilter_queue (libnetfilter-queue-dev) for tests/fault's link delayer
# (tamp_link_delay, `two_hosts.sh --delay`); without it the delayer is not built.
pkg_check_modules(NETFILTER_QUEUE QUIET IMPORTED_TARGET libnetfilter_queue)
if(NETFILTER_QUEUE_FOUND)
  tamp_wrap_dependency(netfilter_queue LIBS PkgConfig::NETFILTER_QUEUE)
else()
  message(STATUS "libnetfilter_queue not found: tamp_link_delay (two_hosts.sh --delay) not built")
endif()

if(TAMP_WITH_DDS)
  find_package(fastrtps 2.9 REQUIRED)    # target `fastrtps`, brings fastcdr and foonathan_memory
  find_program(FASTDDSGEN_EXECUTABLE fastddsgen REQUIRED)
  tamp_wrap_dependency(fastdds LIBS fastrtps fastcdr)
endif()

if(TAMP_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()
if(TAMP_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
