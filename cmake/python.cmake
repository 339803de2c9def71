# The Python module collision_lab (python/collision_lab, catkin_python_setup in
# CMakeLists.txt) and its C++ part collision_lab._core (pybind11): the core's run and io's
# report as Python values, in process (only public headers). Built beside the package's
# generated messages (collision_lab.msg) in the devel space, installed beside them.
# pybind11 takes the Python that catkin found (Python3_FOUND: its new tools), with its headers.
find_package(Python3 REQUIRED COMPONENTS Interpreter Development)
find_package(pybind11 REQUIRED)
pybind11_add_module(collision_lab_python_core MODULE src/python/core_module.cpp)
target_link_libraries(collision_lab_python_core PRIVATE collision_lab_io)
target_compile_definitions(collision_lab_python_core PRIVATE COLLISION_LAB_VERSION="${collision_lab_VERSION}")
set_target_properties(collision_lab_python_core PROPERTIES
  OUTPUT_NAME _core
  LIBRARY_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_PYTHON_DESTINATION}
  # libcollision_lab_io/_core of the devel space, or of the install space once installed.
  BUILD_RPATH ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION}
  INSTALL_RPATH ${CMAKE_INSTALL_PREFIX}/${CATKIN_PACKAGE_LIB_DESTINATION})
install(TARGETS collision_lab_python_core LIBRARY DESTINATION ${CATKIN_PACKAGE_PYTHON_DESTINATION})

# collision_lab_sweep: python3 -m collision_lab.batch (--shard I/N, --merge; docs/python.md). Not
# executable in the source tree, so that rosrun finds only the devel space's or the install's.
catkin_install_python(PROGRAMS scripts/collision_lab_sweep DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
