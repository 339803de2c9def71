"""collision_lab.sweep: many scenes' summaries as one pandas DataFrame, on every core (C++
threads, without the GIL) or over a Dask cluster, with the same table either way."""
import itertools
import math
import os

from . import _core
from ._run import ESCALATION_KEYS, SUMMARY_KEYS, SUMMARY_UNITS, complete_summary, core_job

# A scene dict's keys besides the run() keyword arguments.
_SCENE_KEYS = ('masses', 'positions', 'velocities', 'restitution', 'name')
# Columns of a rejected scene's error (None for the scenes that ran).
ERROR_COLUMNS = ('error_reason', 'error_field', 'error_message')


def scene_list(scenes=None, grid=None, base=None):
    """(parameters, scene dicts): `scenes` as given, or `grid`'s Cartesian product (in
    itertools.product's order, the first parameter slowest) made into scenes by `base`, a
    function(params) -> scene dict or a dict of defaults that each point's values update."""
    if (scenes is None) == (grid is None):
        raise ValueError('give either scenes (a list of scene dicts) or grid (parameter -> values)')
    if scenes is not None:
        return [], [dict(scene) for scene in scenes]
    names = list(grid)
    points = [dict(zip(names, values)) for values in itertools.product(*(grid[n] for n in names))]
    if callable(base):
        made = [dict(base(dict(point))) for point in points]
    else:
        made = [dict(base or {}, **point) for point in points]
    return [(name, [point[name] for point in points]) for name in names], made


def scene_job(scene, options):
    """The collision_lab._core job (core_job) of one scene dict, with `options` as its defaults."""
    merged = dict(options, **scene)
    unknown = set(merged) - set(_SCENE_KEYS) - set(RUN_OPTIONS)
    if unknown:
        raise ValueError('unknown scene keys: %s' % ', '.join(sorted(unknown)))
    missing = [key for key in ('masses', 'positions', 'velocities') if key not in merged]
    if missing:
        raise ValueError('a scene needs masses, positions and velocities; missing: %s' % ', '.join(missing))
    return core_job(**merged)


RUN_OPTIONS = ('ring', 'restitution_model', 'tc', 'elastic_below', 'viscoelastic_speed',
               'max_collisions', 'simulate_to_cap', 'events', 'mode', 'full_state_every')


def summary_row(result):
    """One table row of a collision_lab._core.run_many result: the summary (complete_summary: every
    key of SUMMARY_KEYS, None for a rejected scene), its dict values flattened to
    'key.subkey' columns (lists kept as lists), then the error columns."""
    if 'error' in result:
        summary = dict({key: None for key in SUMMARY_KEYS}, escalation=dict.fromkeys(ESCALATION_KEYS))
    else:
        summary = complete_summary(result['summary'])
    row = {}
    for key, value in summary.items():
        if isinstance(value, dict):
            row.update(('%s.%s' % (key, sub), v) for sub, v in value.items())
        else:
            row[key] = value
    error = result.get('error', {})
    for column in ERROR_COLUMNS:
        row[column] = error.get(column[len('error_'):])
    return row


def run_chunk(jobs, workers=1):
    """The table rows (summary_row) of core_job jobs, run on `workers` C++ threads: the
    function that every Dask task runs."""
    return [summary_row(result) for result in _core.run_many(jobs, workers)]


def sweep_table(rows, parameter_names):
    """The DataFrame of rows (dicts: the parameters, then summary_row's columns): the
    parameters, the summary columns in the order they first appear, the error columns.
    table.attrs['units']: column -> unit of every summary column that has one."""
    import pandas as pd
    table = pd.DataFrame(rows)
    rest = [c for c in table.columns if c not in parameter_names and c not in ERROR_COLUMNS]
    table = table[list(parameter_names) + rest + list(ERROR_COLUMNS)]
    table.attrs['units'] = {column: SUMMARY_UNITS[column] for column in table.columns
                            if column in SUMMARY_UNITS and column not in parameter_names}
    return table


def sweep(scenes=None, *, grid=None, base=None, client=None, workers=None, chunk_size=None, **options):
    """Runs many scenes and returns their summaries as a pandas DataFrame, one row per scene
    in the input's order.

    scenes: a list of scene dicts (masses, positions, velocities; optional restitution,
    name and any run() option); or grid: parameter -> list of values, combined as a
    Cartesian product, with base: a function(params) -> scene dict, or a dict of defaults.
    options: run() options for every scene (a scene's own keys win); events default 'none'
    (the summaries are the point: the CLI's --events none summary).
    Columns: the grid's parameters, then the summary's keys, the same for every model as in
    run() (collision_lab.SUMMARY_KEYS; dicts flattened to 'escalation.decisions', ...; lists
    such as final_velocities kept as lists), then error_reason, error_field, error_message
    (None unless the scene was rejected: its row then has the CLI's JSON error and no
    summary). A collapse is a collapse: collapsed is True or False for every scene that ran
    (collision_count is then the impacts before it), collapse_time [s] None unless collapsed.
    table.attrs['units']: column -> unit ('s', 'm', 'm/s', 'J', 'rad') of the summary's.
    Locally on `workers` C++ threads (default os.cpu_count()). client: a
    dask.distributed.Client; the scenes go in chunks of chunk_size (default: about four
    per worker thread) to the cluster, which runs the same C++ function: the table equals
    the local one bit for bit except compute_time_s, the wall time of each run.
    """
    options.setdefault('events', 'none')
    parameters, made = scene_list(scenes, grid, base)
    jobs = [scene_job(scene, options) for scene in made]
    if client is None:
        rows = run_chunk(jobs, workers or os.cpu_count() or 1)
    else:
        if chunk_size is None:
            threads = sum(client.nthreads().values()) or 1
            chunk_size = max(1, math.ceil(len(jobs) / (4 * threads)))
        chunks = [jobs[i:i + chunk_size] for i in range(0, len(jobs), chunk_size)]
        futures = client.map(run_chunk, chunks, pure=False)
        rows = [row for chunk in client.gather(futures) for row in chunk]
    for name, values in parameters:
        for row, value in zip(rows, values):
            row[name] = value
    return sweep_table(rows, [name for name, _ in parameters])
