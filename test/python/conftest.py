"""Shared fixtures of the Python module's tests: the built collision_lab_cli, the
independent reference that the module's reports are compared with."""
import json
import os
import subprocess

import pytest


def find_program(name):
    """A program of the package in the sourced workspace (devel or install space)."""
    for prefix in os.environ.get('CMAKE_PREFIX_PATH', '').split(':'):
        path = os.path.join(prefix, 'lib', 'collision_lab', name)
        if prefix and os.access(path, os.X_OK):
            return path
    raise RuntimeError(name + ' not found: source build_ros/devel/setup.bash first')


@pytest.fixture(scope='session')
def cli_path():
    return find_program('collision_lab_cli')


@pytest.fixture(scope='session')
def sweep_tool():
    return find_program('collision_lab_sweep')


@pytest.fixture(scope='session')
def cli():
    """cli(args) -> the CLI's --format json document as a dict (its JSON error too)."""
    path = find_program('collision_lab_cli')

    def run(args):
        done = subprocess.run([path, '--format', 'json'] + list(args), capture_output=True, text=True)
        assert done.returncode in (0, 2), done.stderr
        return json.loads(done.stdout)
    return run
