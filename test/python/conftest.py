"""Shared fixtures of the Python module's tests: the built collision_lab_cli, the
independent reference that the module's reports are compared with; and record_bag, the
bags that collision_lab_node records, for read_bag."""
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


LAUNCH = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'bag_nodes.launch')
# run()'s keyword arguments that a preset of the nodes' scenario file carries.
PRESET_KEYS = ('masses', 'positions', 'velocities', 'restitution', 'ring', 'restitution_model', 'tc',
               'elastic_below', 'viscoelastic_speed', 'max_collisions')


@pytest.fixture(scope='session')
def record_bag(tmp_path_factory):
    """record_bag(name, scene, node='plain') -> the path of the bag that collision_lab_node
    recorded of `scene` (run()'s keyword arguments: PRESET_KEYS and mode), once the node has
    closed it. As read_bag.test does, but with two nodes of bag_nodes.launch (node 'plain':
    the defaults; 'to_cap': ~simulate_to_cap true) started by roslaunch with a master of its
    own on a free port. The scene is served as a preset (run_preset) of the nodes' scenario
    file, which carries the restitution model and the ring that run_scene does not."""
    import signal
    import socket
    import time

    import yaml

    folder = tmp_path_factory.mktemp('bags')
    with socket.socket() as free:
        free.bind(('127.0.0.1', 0))
        port = free.getsockname()[1]
    uri = 'http://127.0.0.1:%d' % port
    env = dict(os.environ, ROS_MASTER_URI=uri, ROS_HOME=str(folder / 'ros_home'))
    log = open(folder / 'roslaunch.log', 'w')
    launch = subprocess.Popen(['roslaunch', '-p', str(port), LAUNCH, 'dir:=%s' % folder], env=env, stdout=log,
                              stderr=subprocess.STDOUT, start_new_session=True)
    previous_uri = os.environ.get('ROS_MASTER_URI')
    os.environ['ROS_MASTER_URI'] = uri  # for rospy in this process (imported below)
    try:
        import rospy
        from collision_lab.srv import RunPreset, RunPresetRequest
        services = {node: '/collision_lab/%s/run_preset' % node for node in ('plain', 'to_cap')}
        deadline = time.monotonic() + 60
        for service in services.values():
            while True:
                assert launch.poll() is None, 'roslaunch ended: see %s' % (folder / 'roslaunch.log')
                try:
                    rospy.wait_for_service(service, timeout=1)
                    break
                except rospy.ROSException:
                    assert time.monotonic() < deadline, service + ' did not come up in 60 s'
        presets = {}

        def record(name, scene, node='plain'):
            scene = dict(scene)
            mode = {'full': 0, 'predict': 1, 'summary': 2}[scene.pop('mode', 'full')]
            unknown = set(scene) - set(PRESET_KEYS)
            assert not unknown, 'a preset cannot carry %s' % unknown
            presets[name] = scene
            with open(folder / 'presets.yaml', 'w') as f:
                yaml.safe_dump(presets, f)
            answer = rospy.ServiceProxy(services[node], RunPreset)(RunPresetRequest(name=name, run_id=name,
                                                                                    mode=mode))
            assert answer.ok, answer.message
            path = answer.summary.bag_path
            while not os.path.exists(path):  # renamed from .bag.active when closed
                time.sleep(0.05)
            return path

        yield record
    finally:
        if previous_uri is None:
            os.environ.pop('ROS_MASTER_URI', None)
        else:
            os.environ['ROS_MASTER_URI'] = previous_uri
        os.killpg(launch.pid, signal.SIGINT)  # roslaunch stops its nodes and its master
        try:
            launch.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(launch.pid, signal.SIGKILL)
            launch.wait()
        log.close()
