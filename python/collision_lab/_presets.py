"""The package's named scenes (config/scenarios.yaml, the presets of the CLI, the node and the
class page) and its data files, found from any working directory: preset(name) gives run()'s
keyword arguments, presets() the names and descriptions, data_path(file) a file's path.

Where the files are: catkin installs config/ to <prefix>/share/collision_lab/config; in a
devel space the package's share folder is the source folder, so config/ sits two folders
above this module (python/collision_lab/). config_dir() looks there, then in every
<prefix>/share/collision_lab/config of CMAKE_PREFIX_PATH (the sourced workspace's devel or
install space), then five folders up from this module (an install space not on
CMAKE_PREFIX_PATH: <prefix>/lib/python3/dist-packages/collision_lab/).
"""
import csv
import os

SCENARIOS = 'scenarios.yaml'
# A preset's keys that are run()'s keyword arguments, as the CLI reads them from the file.
_RUN_KEYS = ('masses', 'positions', 'velocities', 'restitution', 'ring', 'restitution_model', 'tc', 'elastic_below',
             'viscoelastic_speed', 'max_collisions')
_NUMBER_LISTS = ('masses', 'positions', 'velocities')


def _candidates(module_file=__file__, prefixes=None):
    here = os.path.dirname(os.path.abspath(module_file))
    yield os.path.normpath(os.path.join(here, '..', '..', 'config'))  # the source folder (devel space)
    if prefixes is None:
        prefixes = os.environ.get('CMAKE_PREFIX_PATH', '').split(os.pathsep)
    for prefix in prefixes:
        if prefix:
            yield os.path.join(prefix, 'share', 'collision_lab', 'config')
    # <prefix>/lib/python3/dist-packages/collision_lab -> <prefix>
    yield os.path.normpath(os.path.join(here, '..', '..', '..', '..', 'share', 'collision_lab', 'config'))


def config_dir(module_file=__file__, prefixes=None):
    """The folder of the package's config files (scenarios.yaml, gas_1000.csv, ...); the
    arguments are for tests. Raises FileNotFoundError, naming the places looked at."""
    looked = []
    for folder in _candidates(module_file, prefixes):
        if os.path.isfile(os.path.join(folder, SCENARIOS)):
            return folder
        looked.append(folder)
    raise FileNotFoundError('collision_lab\'s config folder (with %s) is not in any of: %s; source the workspace '
                            '(devel or install space) first' % (SCENARIOS, ', '.join(looked)))


def data_path(filename):
    """The path of a file of the package's config folder, e.g. data_path('gas_1000.csv')."""
    path = os.path.join(config_dir(), filename)
    if not os.path.isfile(path):
        raise FileNotFoundError('%s is not in collision_lab\'s config folder %s' % (filename, config_dir()))
    return path


def _load():
    import yaml
    with open(os.path.join(config_dir(), SCENARIOS)) as f:
        return yaml.safe_load(f)


def presets():
    """{name: description} of every preset in config/scenarios.yaml, in the file's order."""
    return {name: entry.get('description', '') for name, entry in _load().items()}


def _number(value):
    # PyYAML reads YAML 1.1, where 1.0e4 (no sign in the exponent) is a string; the CLI reads a
    # number, and so does this.
    return float(value)


def read_bodies(path):
    """(masses [kg], positions [m], velocities [m/s]) of a bodies CSV (header
    mass,position,velocity; 'inf' a wall), as lists of floats."""
    masses, positions, velocities = [], [], []
    with open(path, newline='') as f:
        for row in csv.DictReader(f):
            masses.append(float(row['mass']))
            positions.append(float(row['position']))
            velocities.append(float(row['velocity']))
    return masses, positions, velocities


def preset(name):
    """run()'s keyword arguments of the preset `name` (config/scenarios.yaml, as the CLI's
    --scenario FILE --name NAME reads it: a `bodies: FILE` CSV gives the bodies), with
    name=name; collision_lab.run(**preset('granular_ring'), simulate_to_cap=True) runs it.
    Keys the preset does not set are left out (run()'s defaults apply). Raises KeyError with
    the known names."""
    entries = _load()
    if name not in entries:
        raise KeyError('no preset %r in %s; the presets: %s' % (name, os.path.join(config_dir(), SCENARIOS),
                                                                ', '.join(entries)))
    entry = entries[name]
    scene = {'name': name}
    if 'bodies' in entry:
        scene['masses'], scene['positions'], scene['velocities'] = read_bodies(
            os.path.join(config_dir(), entry['bodies']))
    for key in _RUN_KEYS:
        if key not in entry:
            continue
        value = entry[key]
        if key in _NUMBER_LISTS:
            value = [_number(a) for a in value]
        elif key == 'restitution':
            value = [_number(a) for a in value] if isinstance(value, list) else _number(value)
        elif key == 'max_collisions':
            value = int(_number(value))
        elif key != 'restitution_model':
            value = _number(value)
        scene[key] = value
    return scene
