"""collision_lab.sweep: the table of summaries, in order; on C++ threads and on a Dask
cluster of 2 worker processes over TCP, equal bit for bit (but for compute_time_s, the wall
time); and collision_lab_sweep's shards merged into the same table."""
import json
import os
import subprocess

import pandas as pd
import pytest

import collision_lab

INF = float('inf')
GRID = {'heavy': [1.0, 3.0, 100.0, 1e4], 'restitution': [1.0, 0.5, 0.05], 'bodies': [3, 5]}


def scene_of(point):
    """A grid point's scene: `bodies` bodies 1 m apart, the first of mass `heavy` moving in."""
    n = point['bodies']
    return dict(masses=[point['heavy']] + [1.0] * (n - 1), positions=list(range(n - 1, -1, -1)),
                velocities=[-1.0] + [0.0] * (n - 1), restitution=point['restitution'])


BAD_SCENE = dict(masses=[1, 1, 1], positions=[2, 2, 0], velocities=[0, 0, 0])
PI_SCENE = dict(masses=[100, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0], name='pi')


def test_rows_are_the_runs_summaries_in_order():
    scenes = [PI_SCENE, BAD_SCENE, dict(masses=[1, 2, 3, 4], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1])]
    table = collision_lab.sweep(scenes, workers=2)
    assert len(table) == 3
    assert table['collision_count'][0] == 31
    for i in (0, 2):
        summary = collision_lab.run(**{k: v for k, v in scenes[i].items()}, events='none').summary
        for key, value in summary.items():
            if key == 'compute_time_s' or isinstance(value, dict):
                continue
            cell = table[key][i]
            assert cell == value or (value is None and pd.isna(cell)), key
        assert table['escalation.high_precision'][i] == summary['escalation']['high_precision']
        assert table['error_reason'][i] is None
    assert table['error_reason'][1] == 'POSITIONS_COINCIDENT'
    assert table['error_field'][1] == 'positions'
    assert 'A and B must start apart' in table['error_message'][1]
    assert pd.isna(table['collision_count'][1])


def test_grid_is_a_cartesian_product_with_parameter_columns():
    table = collision_lab.sweep(grid=GRID, base=scene_of, workers=2)
    assert len(table) == 4 * 3 * 2
    assert list(table.columns[:3]) == ['heavy', 'restitution', 'bodies']
    assert list(table['heavy'][:6]) == [1.0] * 6 and list(table['bodies'][:4]) == [3, 5, 3, 5]
    # m_A = 100 m_B elastic, with three bodies: no wall, so not the 31 of the pi billiard.
    row = table[(table.heavy == 100.0) & (table.restitution == 1.0) & (table.bodies == 3)].iloc[0]
    assert row['collision_count'] == collision_lab.run(**scene_of(dict(heavy=100.0, restitution=1.0, bodies=3)),
                                                       events='none').summary['collision_count']
    # A dict base: the grid point's values replace its keys.
    pis = collision_lab.sweep(grid={'masses': [[100, 1, INF], [1e4, 1, INF]]},
                              base=dict(positions=[2, 1, 0], velocities=[-1, 0, 0]))
    assert pis['collision_count'].tolist() == [31, 314]


def test_one_thread_equals_every_core():
    one = collision_lab.sweep(grid=GRID, base=scene_of, workers=1).drop(columns='compute_time_s')
    every = collision_lab.sweep(grid=GRID, base=scene_of).drop(columns='compute_time_s')
    assert one.equals(every)


def test_dask_sweep_equals_local_sweep():
    distributed = pytest.importorskip('distributed')
    scenes = [scene_of(dict(heavy=h, restitution=e, bodies=n)) for h in GRID['heavy']
              for e in GRID['restitution'] for n in GRID['bodies']] + [BAD_SCENE, PI_SCENE]
    local = collision_lab.sweep(scenes, workers=2, max_collisions=5000)
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, protocol='tcp',
                                  host='127.0.0.1', dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        assert cluster.scheduler_address.startswith('tcp://')
        assert len(client.nthreads()) == 2
        remote = collision_lab.sweep(scenes, client=client, chunk_size=5, max_collisions=5000)
    assert local.drop(columns='compute_time_s').equals(remote.drop(columns='compute_time_s'))
    assert (local.columns == remote.columns).all() and len(local) == len(scenes)
    assert local['error_reason'].tolist()[-2:] == ['POSITIONS_COINCIDENT', None]


SWEEP_YAML = """\
grid:
  heavy: [1.0, 3.0, 100.0, 10000.0]
  restitution: [1.0, 0.5]
base:
  masses: [$heavy, 1, 1, .inf]
  positions: [3, 2, 1, 0]
  velocities: [-1, 0, 0, 0]
  restitution: $restitution
options:
  max_collisions: 2000
"""


def read_lines(path):
    rows = [json.loads(line) for line in open(path)]
    for row in rows:
        del row['compute_time_s']
    return rows


def test_shell_shards_merged_equal_the_unsharded_sweep(tmp_path, sweep_tool):
    (tmp_path / 'sweep.yaml').write_text(SWEEP_YAML)
    tool = sweep_tool
    # As docs/python.md's loop, GNU parallel's and Slurm's array stand-in: 3 shards, one merge;
    # the module's form and the installed program's.
    script = ('set -e\n'
              'for i in 0 1 2; do python3 -m collision_lab.batch sweep.yaml --shard $i/3 -o shard_$i.jsonl; done\n'
              '"$TOOL" sweep.yaml --merge shard_*.jsonl -o merged.jsonl\n'
              '"$TOOL" sweep.yaml --merge shard_*.jsonl -o merged.csv\n'
              '"$TOOL" sweep.yaml -o whole.jsonl --workers 2\n')
    subprocess.run(['bash', '-c', script], cwd=tmp_path, check=True, env=dict(os.environ, TOOL=tool))
    sizes = [len(open(tmp_path / ('shard_%d.jsonl' % i)).readlines()) for i in range(3)]
    assert sizes == [2, 3, 3]
    merged, whole = read_lines(tmp_path / 'merged.jsonl'), read_lines(tmp_path / 'whole.jsonl')
    assert merged == whole and [row['scene'] for row in merged] == list(range(8))
    # The same table as collision_lab.sweep in process.
    heavy = [1.0, 3.0, 100.0, 10000.0]
    expected = collision_lab.sweep(
        grid={'heavy': heavy, 'restitution': [1.0, 0.5]}, max_collisions=2000,
        base=lambda p: dict(masses=[p['heavy'], 1, 1, INF], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 0],
                            restitution=p['restitution']))
    table = pd.read_csv(tmp_path / 'merged.csv', index_col='scene')
    assert table['collision_count'].tolist() == expected['collision_count'].tolist()
    assert table['model'].tolist() == expected['model'].tolist()
    assert [row['collision_count'] for row in merged] == expected['collision_count'].tolist()
    # The pi billiard's 31 with m_A = 100 m_B needs the wall directly behind B: here a third
    # body sits between them, so the count is the engine's, and it is a number.
    assert all(isinstance(row['collision_count'], int) for row in merged)


def test_merge_refuses_a_missing_shard(tmp_path, sweep_tool):
    (tmp_path / 'sweep.yaml').write_text(SWEEP_YAML)
    tool = sweep_tool
    subprocess.run([tool, 'sweep.yaml', '--shard', '0/2', '-o', 'a.jsonl'], cwd=tmp_path, check=True)
    done = subprocess.run([tool, 'sweep.yaml', '--merge', 'a.jsonl', '-o', 'm.jsonl'], cwd=tmp_path,
                          capture_output=True, text=True)
    assert done.returncode != 0 and '4 of 8 scenes missing' in done.stderr


def three_equal_masses(e):
    return dict(masses=[1, 1, 1], positions=[2, 1, 0], velocities=[-1, 0, 0], restitution=e)


def test_a_collapse_is_a_collapse_in_the_table():
    """Three equal masses collapse below r_c = 7 - 4 sqrt 3 = 0.072 (docs/physics.md): at
    e = 0.05 after 8 impacts, at t = 3.5 s; at e = 0.5 they spiral apart, and elastic (the
    three-body report, which has no collapse keys) they never collapse. Every row says
    which, as a bool, with the collapse time."""
    table = collision_lab.sweep(grid={'e': [0.05, 0.5, 1.0]}, base=lambda p: three_equal_masses(p['e']))
    assert table['collapsed'].dtype == bool
    assert table['collapsed'].tolist() == [True, False, False]
    assert table['collapse_time'][0] == 3.5 and table['collapse_time'][1:].isna().all()
    assert table['collision_count'].tolist()[0::2] == [8, 2]  # equal elastic masses: 2 exchanges
    # The same as a run with every event: the collapse is its last event.
    for i, e in enumerate([0.05, 0.5, 1.0]):
        run = collision_lab.run(**three_equal_masses(e))
        assert bool(table['collapsed'][i]) is run.summary['collapsed'] is ('collapse' in run.events['kind'])
    # A rejected scene has no run: its row says nothing (None), the others still say.
    mixed = collision_lab.sweep([three_equal_masses(0.05), BAD_SCENE, three_equal_masses(1.0)])
    assert mixed['collapsed'].tolist() == [True, None, False]


def test_the_docs_sweep_pivot_shows_collapses_as_collapses():
    """docs/python.md's sweep example, run as written: its pivot says '8 + collapse' where
    the pi billiard's blocks collapse (issue 47: 86 of 122 inelastic rows were shown as '8'),
    and the collapse counts its comment gives."""
    import re
    docs = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'docs', 'python.md')).read()
    section = docs[docs.index('## Sweeps: `collision_lab.sweep`'):]
    code = re.search(r'```python\n(.*?)```', section, re.S).group(1)
    names = {}
    exec(code, names)
    table, counts, collapses = names['table'], names['counts'], names['collapses']
    assert counts.loc[1e6, 1.0] == '3141'  # the pi billiard's digits: elastic, no collapse
    assert collapses[1.0] == 0 and collapses[0.5] + collapses[0.9] == table['collapsed'].sum() > 0
    for _, row in table.iterrows():
        assert counts.loc[row['heavy'], row['e']].endswith(' + collapse') is bool(row['collapsed'])
        if row['collapsed']:
            assert counts.loc[row['heavy'], row['e']] == '%d + collapse' % row['collision_count']
    said = dict(re.findall(r'([01]\.\d): (\d+)', code.split('collapses =')[1]))
    assert {float(e): int(n) for e, n in said.items()} == collapses.to_dict()
