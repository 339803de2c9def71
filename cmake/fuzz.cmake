# libFuzzer target over the core (included by CMakeLists.txt with -DCOLLISION_LAB_FUZZ=ON).
# Needs clang: configure with CC=clang CXX=clang++ in a folder of its own, then build only
# collision_lab_core_fuzzer (scripts/fuzz.sh does all of it). The core is instrumented
# for coverage and built with ASan and UBSan; every UBSan finding aborts.
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "COLLISION_LAB_FUZZ needs clang (CC=clang CXX=clang++), not ${CMAKE_CXX_COMPILER_ID}")
endif()
set(COLLISION_LAB_FUZZ_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g)
target_compile_options(collision_lab_core PRIVATE -fsanitize=fuzzer-no-link ${COLLISION_LAB_FUZZ_FLAGS})

add_executable(collision_lab_core_fuzzer fuzz/core_fuzzer.cpp)
target_link_libraries(collision_lab_core_fuzzer collision_lab_core)
target_compile_options(collision_lab_core_fuzzer PRIVATE -fsanitize=fuzzer ${COLLISION_LAB_FUZZ_FLAGS})
target_link_options(collision_lab_core_fuzzer PRIVATE -fsanitize=fuzzer,address,undefined)
install(TARGETS collision_lab_core_fuzzer RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# The N-body path of every front end (planScene, runScene with the event visitors): any N,
# walls, rings, per-pair restitution and the restitution models.
add_executable(collision_lab_nbody_fuzzer fuzz/nbody_fuzzer.cpp)
target_link_libraries(collision_lab_nbody_fuzzer collision_lab_core)
target_compile_options(collision_lab_nbody_fuzzer PRIVATE -fsanitize=fuzzer ${COLLISION_LAB_FUZZ_FLAGS})
target_link_options(collision_lab_nbody_fuzzer PRIVATE -fsanitize=fuzzer,address,undefined)
install(TARGETS collision_lab_nbody_fuzzer RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
