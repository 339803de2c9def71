# Benchmarks (not tests). Included by the top-level CMakeLists.txt.
#   collision_lab_bench_core      ns per collision of the core vs a lean double loop (issue 2)
#   collision_lab_bench_nbody     ns per impact of the N-body engine vs a lean heap loop, memory (issue 10)
#   collision_lab_bench_restitution  count against e across r_c, three equal masses (issue 11)
#   collision_lab_bench_gas       worst case of seeded granular gases, N = 10 to 1000, e = 0.1 to 0.99 (issue 21)
#   collision_lab_speed_vs_error  speed against error vs fixed stepping and real engines (issue 4)
#   collision_lab_hard_cases      adaptive precision on the hard cases of physics.md (issue 4)
#   collision_lab_node_throughput, collision_lab_relay_node   the whole node over loopback
#                                 (issue 4; built with the ROS layer; bench/node/node_throughput.launch)
#   collision_lab_recording_bench the node's recording against rosbag record (issue 13;
#                                 bench/node/recording_vs_rosbag.launch)
# Real engines are optional: each is compiled in only when found. GMP (exact reference
# trajectories) is required by the last two; without it they are skipped with a message.

find_package(PkgConfig QUIET)
find_path(COLLISION_LAB_GMPXX_INCLUDE gmpxx.h)
find_library(COLLISION_LAB_GMPXX_LIBRARY gmpxx)
find_library(COLLISION_LAB_GMP_LIBRARY gmp)
# matplotlib lives in Debian's Python; the pyenv python3 that may come first on PATH lacks it.
find_program(COLLISION_LAB_PLOT_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT COLLISION_LAB_PLOT_PYTHON)
  find_program(COLLISION_LAB_PLOT_PYTHON NAMES python3)
endif()

add_executable(collision_lab_bench_core bench/bench_core.cpp)
target_include_directories(collision_lab_bench_core PRIVATE bench/common src/core/nbody)  # src/core/nbody: double-double, the floor measured
target_link_libraries(collision_lab_bench_core PRIVATE collision_lab_core)

add_executable(collision_lab_bench_nbody bench/bench_nbody.cpp)
target_include_directories(collision_lab_bench_nbody PRIVATE src/core/nbody)  # the engine's queue, compared
target_link_libraries(collision_lab_bench_nbody PRIVATE collision_lab_core)
target_compile_definitions(collision_lab_bench_nbody PRIVATE COLLISION_LAB_CONFIG_DIR="${PROJECT_SOURCE_DIR}/config")

add_executable(collision_lab_bench_restitution bench/bench_restitution.cpp)
target_link_libraries(collision_lab_bench_restitution PRIVATE collision_lab_core)
target_compile_definitions(collision_lab_bench_restitution PRIVATE COLLISION_LAB_DOCS_DIR="${PROJECT_SOURCE_DIR}/docs")
add_executable(collision_lab_bench_gas bench/bench_gas.cpp)
target_include_directories(collision_lab_bench_gas PRIVATE test/core/nbody)  # the tests' seeded gas, one home
target_link_libraries(collision_lab_bench_gas PRIVATE collision_lab_core)
# Installed too, so that an install space can be benchmarked with rosrun.
install(TARGETS collision_lab_bench_core collision_lab_bench_nbody collision_lab_bench_restitution collision_lab_bench_gas
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(TARGET collision_lab_ros)
  add_executable(collision_lab_relay_node bench/node/relay_node.cpp)
  target_link_libraries(collision_lab_relay_node PRIVATE collision_lab_ros)
  add_executable(collision_lab_node_throughput bench/node/node_throughput.cpp)
  target_link_libraries(collision_lab_node_throughput PRIVATE collision_lab_ros)
  add_executable(collision_lab_recording_bench bench/node/recording_vs_rosbag.cpp)
  target_link_libraries(collision_lab_recording_bench PRIVATE collision_lab_ros)
  set_target_properties(collision_lab_relay_node collision_lab_node_throughput collision_lab_recording_bench PROPERTIES
    RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
  install(TARGETS collision_lab_relay_node collision_lab_node_throughput collision_lab_recording_bench
    RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endif()

if(NOT (COLLISION_LAB_GMPXX_INCLUDE AND COLLISION_LAB_GMPXX_LIBRARY AND COLLISION_LAB_GMP_LIBRARY))
  message(STATUS "collision_lab bench: GMP (libgmp-dev) not found; speed_vs_error and hard_cases not built")
  return()
endif()

add_library(collision_lab_bench_common STATIC
  bench/common/exact_trajectory.cpp
  bench/engines/fixed_step.cpp
  bench/engines/stepped_methods.cpp)
target_include_directories(collision_lab_bench_common PUBLIC bench/common bench/engines)
target_include_directories(collision_lab_bench_common PRIVATE ${COLLISION_LAB_GMPXX_INCLUDE})
target_link_libraries(collision_lab_bench_common PUBLIC collision_lab_core
  ${COLLISION_LAB_GMPXX_LIBRARY} ${COLLISION_LAB_GMP_LIBRARY})

# Engines: each in its own object library, so an engine's compile definitions (Bullet's
# BT_USE_DOUBLE_PRECISION) stay with its own translation unit.
set(_bench_engines "")
if(PkgConfig_FOUND)
  pkg_check_modules(COLLISION_LAB_BULLET QUIET IMPORTED_TARGET bullet-float64)
  if(NOT COLLISION_LAB_BULLET_FOUND)
    pkg_check_modules(COLLISION_LAB_BULLET QUIET IMPORTED_TARGET bullet)
  endif()
  pkg_check_modules(COLLISION_LAB_ODE QUIET IMPORTED_TARGET ode)
endif()
find_package(box2d CONFIG QUIET)

if(COLLISION_LAB_BULLET_FOUND)
  add_library(collision_lab_bench_bullet OBJECT bench/engines/bullet_engine.cpp)
  target_link_libraries(collision_lab_bench_bullet PUBLIC PkgConfig::COLLISION_LAB_BULLET collision_lab_core)
  target_include_directories(collision_lab_bench_bullet PRIVATE bench/engines)
  target_compile_definitions(collision_lab_bench_bullet PRIVATE COLLISION_LAB_BENCH_HAVE_BULLET)
  target_compile_options(collision_lab_bench_bullet PRIVATE -Wno-unused-parameter)
  list(APPEND _bench_engines bullet)
endif()
if(COLLISION_LAB_ODE_FOUND)
  add_library(collision_lab_bench_ode OBJECT bench/engines/ode_engine.cpp)
  target_link_libraries(collision_lab_bench_ode PUBLIC PkgConfig::COLLISION_LAB_ODE collision_lab_core)
  target_include_directories(collision_lab_bench_ode PRIVATE bench/engines)
  target_compile_definitions(collision_lab_bench_ode PRIVATE COLLISION_LAB_BENCH_HAVE_ODE)
  list(APPEND _bench_engines ode)
endif()
if(TARGET box2d::box2d)
  add_library(collision_lab_bench_box2d OBJECT bench/engines/box2d_engine.cpp)
  target_link_libraries(collision_lab_bench_box2d PUBLIC box2d::box2d collision_lab_core)
  target_include_directories(collision_lab_bench_box2d PRIVATE bench/engines)
  target_compile_definitions(collision_lab_bench_box2d PRIVATE COLLISION_LAB_BENCH_HAVE_BOX2D)
  list(APPEND _bench_engines box2d)
endif()
message(STATUS "collision_lab bench: engines found: ${_bench_engines}")
foreach(_engine IN LISTS _bench_engines)
  string(TOUPPER ${_engine} _ENGINE)
  target_link_libraries(collision_lab_bench_common PUBLIC collision_lab_bench_${_engine})
  target_compile_definitions(collision_lab_bench_common PRIVATE COLLISION_LAB_BENCH_HAVE_${_ENGINE})
endforeach()

add_executable(collision_lab_speed_vs_error bench/speed_vs_error.cpp bench/common/report.cpp)
target_link_libraries(collision_lab_speed_vs_error PRIVATE collision_lab_bench_common)
target_compile_definitions(collision_lab_speed_vs_error PRIVATE
  COLLISION_LAB_BENCH_DIR="${PROJECT_SOURCE_DIR}/bench"
  COLLISION_LAB_DOCS_DIR="${PROJECT_SOURCE_DIR}/docs"
  COLLISION_LAB_PLOT_PYTHON="${COLLISION_LAB_PLOT_PYTHON}")

add_executable(collision_lab_hard_cases bench/hard_cases.cpp bench/common/report.cpp)
target_link_libraries(collision_lab_hard_cases PRIVATE collision_lab_bench_common)
target_compile_definitions(collision_lab_hard_cases PRIVATE
  COLLISION_LAB_DOCS_DIR="${PROJECT_SOURCE_DIR}/docs")
install(TARGETS collision_lab_speed_vs_error collision_lab_hard_cases
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
