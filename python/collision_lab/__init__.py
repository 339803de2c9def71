"""collision_lab in Python: the exact engine in process (docs/python.md).

run() and predict() run one scene as collision_lab_cli does (its JSON report, as dicts and
numpy arrays); sweep() runs many, on every core or on a Dask cluster; read_bag() opens a
run the ROS node recorded. collision_lab.msg holds the package's ROS messages.
"""
from ._run import Run, SceneError, body_name, predict, run
from ._sweep import sweep

__all__ = ['Run', 'SceneError', 'body_name', 'predict', 'run', 'sweep']
