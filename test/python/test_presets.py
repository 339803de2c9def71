"""The package's presets and data files from Python (issue 47: notebooks that run from any copy,
with data loaded from the package): collision_lab.preset(name) is run()'s keyword arguments of
config/scenarios.yaml's scene, read here again with yaml and csv; the config folder is found
from any working directory, in the devel space's layout (the source folder) and in an install
space's (<prefix>/share/collision_lab/config, through CMAKE_PREFIX_PATH or from the module's
own place)."""
import csv
import math
import os
import shutil

import pytest
import yaml

import collision_lab as cl
from collision_lab import _presets

CONFIG = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'config'))


def test_config_folder_found_from_any_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert os.path.samefile(_presets.config_dir(), CONFIG)
    assert os.path.samefile(cl.data_path('gas_1000.csv'), os.path.join(CONFIG, 'gas_1000.csv'))


def install_space(prefix):
    """A copy of an install space's layout: the module in lib/python3/dist-packages, the
    config files in share/collision_lab/config."""
    module = prefix / 'lib' / 'python3' / 'dist-packages' / 'collision_lab' / '_presets.py'
    module.parent.mkdir(parents=True)
    shutil.copy(_presets.__file__, module)
    shutil.copytree(CONFIG, prefix / 'share' / 'collision_lab' / 'config')
    return str(module)


def test_config_folder_in_an_install_space(tmp_path):
    module = install_space(tmp_path / 'install')
    expected = str(tmp_path / 'install' / 'share' / 'collision_lab' / 'config')
    # From the module's own place (no CMAKE_PREFIX_PATH), and through CMAKE_PREFIX_PATH.
    assert _presets.config_dir(module_file=module, prefixes=[]) == expected
    elsewhere = str(tmp_path / 'elsewhere' / 'collision_lab' / '_presets.py')
    assert _presets.config_dir(module_file=elsewhere, prefixes=['', str(tmp_path / 'install')]) == expected


def test_no_config_folder_says_where_it_looked(tmp_path):
    with pytest.raises(FileNotFoundError, match='source the workspace'):
        _presets.config_dir(module_file=str(tmp_path / 'a' / 'b' / 'collision_lab' / '_presets.py'),
                            prefixes=[str(tmp_path)])


def test_granular_ring_is_the_files_scene():
    scene = cl.preset('granular_ring')
    with open(os.path.join(CONFIG, 'gas_1000.csv'), newline='') as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 1000
    assert scene['masses'] == [float(row['mass']) for row in rows]
    assert scene['positions'] == [float(row['position']) for row in rows]
    assert scene['velocities'] == [float(row['velocity']) for row in rows]
    # config/scenarios.yaml, granular_ring: ring 1000, restitution 0.9, tc model, t_c 1 ms, cap 100,000.
    assert {k: v for k, v in scene.items() if k not in ('masses', 'positions', 'velocities')} == {
        'name': 'granular_ring', 'ring': 1000.0, 'restitution': 0.9, 'restitution_model': 'tc', 'tc': 0.001,
        'max_collisions': 100000}


def test_every_preset_runs_as_run_arguments():
    with open(os.path.join(CONFIG, 'scenarios.yaml')) as f:
        entries = yaml.safe_load(f)
    assert list(cl.presets()) == list(entries)
    assert cl.presets()['pi_digits_2'] == entries['pi_digits_2']['description']
    for name in entries:
        scene = cl.preset(name)
        assert set(scene) <= set(cl.SCENE_KEYS), name
        run = cl.run(**scene, mode='predict', events='none')
        assert run.scene['name'] == name
        assert len(run.masses) == len(scene['masses'])
    # YAML 1.1 reads 1.0e4 as a string; the preset has the number, as the CLI.
    assert cl.preset('pi_digits_3')['masses'] == [1.0e4, 1.0, math.inf]
    assert cl.run(**cl.preset('pi_digits_3'), events='none').summary['collision_count'] == 314
    assert cl.preset('two_carts_inelastic')['restitution'] == 0.8


def test_unknown_preset_names_the_known_ones():
    with pytest.raises(KeyError, match='granular_ring'):
        cl.preset('granular_rink')
