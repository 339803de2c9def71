# The Python module collision_lab (python/collision_lab), for catkin_python_setup():
# its C++ part _core is built by cmake/python.cmake.
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=['collision_lab'], package_dir={'': 'python'}))
