"""collision_lab in Python: the exact engine in process (docs/python.md).

run() and predict() run one scene as collision_lab_cli does (its JSON report, as dicts and
numpy arrays); sweep() runs many, on every core or on a Dask cluster; read_bag() opens a
run the ROS node recorded; preset() a named scene of config/scenarios.yaml. A Run's summary has the same keys (SUMMARY_KEYS) from all three,
for every model, and its scene (SCENE_KEYS) goes back into run(**scene).
collision_lab.msg holds the package's ROS messages.
"""
from pkgutil import extend_path

# In a catkin devel space the package has two folders: this source folder and the devel
# space's (the built _core, the generated msg). A process that finds this one first (it
# inherits the sys.path that the devel __init__ extends, as a Dask worker does) gets both.
__path__ = extend_path(__path__, __name__)

from ._core import version as __version__
from ._run import SCENE_KEYS, SUMMARY_KEYS, CapWarning, Run, RunInterrupted, SceneError, body_name, predict, run
from ._sweep import sweep
from ._bag import read_bag
from ._presets import data_path, preset, presets

__all__ = ['CapWarning', 'Run', 'RunInterrupted', 'SCENE_KEYS', 'SUMMARY_KEYS', 'SceneError', 'body_name', 'data_path', 'plot', 'predict',
           'preset', 'presets', 'read_bag', 'run', 'sweep']


def __getattr__(name):
    """collision_lab.plot, imported on first use (it loads matplotlib)."""
    if name == 'plot':
        import importlib
        return importlib.import_module('.plot', __name__)
    raise AttributeError('module %r has no attribute %r' % (__name__, name))
