"""collision_lab.run and predict against collision_lab_cli's JSON, value for value, on a
scene of every model; the events as numpy arrays and a DataFrame. The module binds the core
directly (no JSON text), so the CLI's JSON, parsed here, is an independent path to the same
values."""
import math

import numpy as np
import pytest

import collision_lab

INF = float('inf')

# (model, run()'s arguments, the CLI's arguments for the same scene, written by hand)
SCENES = [
    ('no_collisions', dict(masses=[1, 2, 3], positions=[2, 1, 0], velocities=[1, 0, -1]),
     '--masses 1,2,3 --positions 2,1,0 --velocities 1,0,-1'),
    ('two_body', dict(masses=[3, 1], positions=[1, 0], velocities=[-1, 1]),
     '--masses 3,1 --positions 1,0 --velocities -1,1'),
    ('three_body_rotation', dict(masses=[100, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0]),
     '--masses 100,1,inf --positions 2,1,0 --velocities -1,0,0'),
    ('three_body_spiral', dict(masses=[1, 1, 1], positions=[2, 1, 0], velocities=[-1, 0, 0], restitution=0.05),
     '--masses 1,1,1 --positions 2,1,0 --velocities -1,0,0 --restitution 0.05'),
    ('ghosts', dict(masses=[1, 1, 1, 1], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1]),
     '--masses 1,1,1,1 --positions 3,2,1,0 --velocities -1,0,0,1'),
    ('sticky', dict(masses=[1, 2, 3, 4], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1], restitution=0),
     '--masses 1,2,3,4 --positions 3,2,1,0 --velocities -1,0,0,1 --restitution 0'),
    ('two_walls_infinite', dict(masses=[INF, 1, INF], positions=[1, 0.5, 0], velocities=[0, 1, 0]),
     '--masses inf,1,inf --positions 1,0.5,0 --velocities 0,1,0'),
    ('box_infinite', dict(masses=[INF, 1, 2, INF], positions=[3, 2, 1, 0], velocities=[0, 1, -1, 0],
                          restitution=0.5, max_collisions=200),
     '--masses inf,1,2,inf --positions 3,2,1,0 --velocities 0,1,-1,0 --restitution 0.5 --max-collisions 200'),
    ('event_engine', dict(masses=[1, 2, 3, 4, 5], positions=[4, 3, 2, 1, 0], velocities=[-1, 0.5, 0, 0.2, 1]),
     '--masses 1,2,3,4,5 --positions 4,3,2,1,0 --velocities -1,0.5,0,0.2,1'),
    # Numbers of 16 and 17 significant digits arrive as the same doubles.
    ('event_engine', dict(masses=[0.3333333333333333, 1.4142135623730951, 3.141592653589793, 2.718281828459045],
                          positions=[3.3000000000000003, 2.1, 1.05, 0.0],
                          velocities=[-0.14285714285714285, 0.2, 1e-300, 0.3333333333333333],
                          restitution=0.91370000000000001),
     '--masses 0.3333333333333333,1.4142135623730951,3.141592653589793,2.718281828459045 '
     '--positions 3.3000000000000003,2.1,1.05,0 --velocities -0.14285714285714285,0.2,1e-300,0.3333333333333333 '
     '--restitution 0.9137'),
    ('event_engine', dict(masses=[1, 2, 3], positions=[3, 2, 1], velocities=[1, 0, -1], ring=10),
     '--masses 1,2,3 --positions 3,2,1 --velocities 1,0,-1 --ring 10'),
    ('event_engine', dict(masses=[1, 2, 3, 1.5, 1], positions=[4, 3, 2, 1, 0], velocities=[-1, 0.5, 0, 0.2, 1],
                          restitution=0.8, restitution_model='tc', tc=1e-3, ring=10, max_collisions=500),
     '--masses 1,2,3,1.5,1 --positions 4,3,2,1,0 --velocities -1,0.5,0,0.2,1 --restitution 0.8 '
     '--restitution-model tc --tc 0.001 --ring 10 --max-collisions 500'),
    ('event_engine', dict(masses=[1, 2, 3, 4], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1],
                          events='first:3', simulate_to_cap=True, mode='summary'),
     '--masses 1,2,3,4 --positions 3,2,1,0 --velocities -1,0,0,1 --events first:3 --simulate-to-cap '
     '--mode summary'),
    ('three_body_rotation', dict(masses=[1e4, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0], mode='predict'),
     '--masses 10000,1,inf --positions 2,1,0 --velocities -1,0,0 --mode predict'),
]


def without_wall_time(report):
    """The report without compute_time_s, the run's wall time."""
    summary = dict(report['summary'])
    del summary['compute_time_s']
    return dict(report, summary=summary)


def same_as_json(ours, theirs):
    """Is every value of `ours` (numpy) the JSON's: equal, or not finite where the JSON has
    null (it writes NaN and the infinities as null)? A null row, or a key the event leaves out
    (the full state of a lean event, or above 64 bodies), stands for a row of NaN."""
    ours = np.asarray(ours)
    if theirs is None:
        return not np.any(np.isfinite(ours))
    if isinstance(theirs, list):
        return len(ours) == len(theirs) and all(same_as_json(o, t) for o, t in zip(ours, theirs))
    return ours.item() == theirs


def _many_bodies(n):
    """A scene of n > 64 bodies (beyond the records' full state) and the CLI's arguments for it."""
    kwargs = dict(masses=[1.0 + (i % 3) for i in range(n)], positions=[float(n - i) for i in range(n)],
                  velocities=[-1.0] + [0.0] * (n - 2) + [1.0], events='first:200')
    lists = ' '.join('--%s %s' % (key, ','.join(repr(v) for v in kwargs[key]))
                     for key in ('masses', 'positions', 'velocities'))
    return kwargs, lists + ' --events first:200'


SCENES.append(('event_engine',) + _many_bodies(70))
SCENES.append(('event_engine', dict(masses=[1, 2, 3, 1.5, 1], positions=[4, 3, 2, 1, 0],
                                    velocities=[-1, 0.5, 0, 0.2, 1], full_state_every=3),
               '--masses 1,2,3,1.5,1 --positions 4,3,2,1,0 --velocities -1,0.5,0,0.2,1 --full-state-every 3'))


@pytest.mark.parametrize('model,kwargs,cli_args', SCENES, ids=[s[0] for s in SCENES])
def test_run_equals_cli_json(cli, model, kwargs, cli_args):
    expected = cli(cli_args.split())
    run = collision_lab.run(**kwargs)
    assert run.model == expected['summary']['model'] == model
    json_events = expected.pop('events')
    assert 'events' not in run.report  # they are run.events
    assert without_wall_time(run.report) == without_wall_time(expected)
    # The summary: the CLI's keys and values, completed to the keys of every model (test_round_trip.py).
    for key, value in expected['summary'].items():
        if key == 'escalation':
            assert value.items() <= run.summary[key].items()
        elif key != 'compute_time_s':
            assert run.summary[key] == value, key
    assert run.report['scene'] == expected['scene']
    assert run.options == expected['options'] and run.units == expected['units']
    assert run.model_reason == expected['summary']['model_reason']
    events = json_events
    for key in ('kind', 'pair', 'index', 'pair_index', 'first_moved', 'last_moved', 'cluster_impact'):
        assert run.events[key].tolist() == [e[key] for e in events], key
    assert [list(u) for u in run.events['uncertified']] == [e.get('uncertified', []) for e in events]
    for key in ('time', 'position', 'restitution', 'energy_lost', 'total_energy', 'total_momentum',
                'pair_velocities_before', 'pair_velocities_after', 'pair_energy_transfer'):
        assert all(same_as_json(ours, e.get(key)) for ours, e in zip(run.events[key], events)), key
    for key in ('positions', 'velocities_before', 'velocities_after', 'energy_transfer', 'kinetic_energy_after'):
        assert run.events[key].shape == (len(events), len(kwargs['masses']))
        assert all(same_as_json(ours, e.get(key)) for ours, e in zip(run.events[key], events)), key
    for key in ('predicted_velocities_after', 'paper_velocities_after', 'predicted_energy_transfer',
                'paper_energy_transfer'):
        given = [e.get(key) for e in events]
        assert (key in run.events) == any(row is not None for row in given), key
        if key in run.events:
            assert all(same_as_json(ours, row) for ours, row in zip(run.events[key], given)), key
    table = run.to_pandas()
    assert len(table) == len(events)
    names = [collision_lab.body_name(i) for i in range(len(kwargs['masses']))]
    assert run.names == names
    if len(names) <= 64:
        for i, name in enumerate(names):
            np.testing.assert_array_equal(table['v_' + name], run.events['velocities_after'][:, i])
            np.testing.assert_array_equal(table['x_' + name], run.events['positions'][:, i])
    else:  # no per-body arrays: no all-NaN columns; state_at gives the states
        assert not [c for c in table.columns if c.startswith(('v_', 'x_'))]
    np.testing.assert_array_equal(run.masses, np.array(kwargs['masses'], dtype=float))


def test_pi_billiard_counts_and_three_body_arrays():
    for heavy, count in ((100, 31), (1e4, 314), (1e6, 3141)):
        run = collision_lab.run([heavy, 1, INF], [2, 1, 0], [-1, 0, 0])
        assert run.summary['collision_count'] == count
        assert len(run.events['time']) == count
    # The rotation model's velocities at each impact are given beside the simulated ones.
    assert run.events['predicted_velocities_after'].shape == (3141, 3)
    np.testing.assert_allclose(run.events['predicted_velocities_after'], run.events['velocities_after'],
                               rtol=0, atol=1e-9)


def test_spiral_collapse_is_an_event():
    run = collision_lab.run([1, 1, 1], [2, 1, 0], [-1, 0, 0], 0.05)
    assert run.events['kind'].tolist() == ['impact'] * 8 + ['collapse']
    assert run.summary['collapsed'] is True
    assert run.summary['collapse_time'] == 3.5
    np.testing.assert_allclose(run.events['velocities_after'][-1], [-1 / 3] * 3, rtol=1e-15)


def test_prediction_equals_predict():
    for args in (([100, 1, INF], [2, 1, 0], [-1, 0, 0]), ([1, 1, 1, 1], [3, 2, 1, 0], [-1, 0, 0, 1])):
        run = collision_lab.run(*args)
        assert run.prediction == collision_lab.predict(*args)
        assert run.prediction['model'] == run.model
    assert collision_lab.predict([1e6, 1, INF], [2, 1, 0], [-1, 0, 0])['predicted_collision_count'] == 3141


def test_body_names_past_z():
    n = 30
    run = collision_lab.run([1.0] * n, list(range(n, 0, -1)), [0.0] * (n - 1) + [-1.0], events='none')
    assert run.names[:2] == ['A', 'B'] and run.names[25] == 'Z' and run.names[26] == '#26'
    assert list(run.to_pandas().columns[-2:]) == ['x_#28', 'x_#29']


def test_temperature_csv_as_the_cli(cli, tmp_path):
    ours, theirs = tmp_path / 'ours.csv', tmp_path / 'cli.csv'
    collision_lab.run([1, 2, 1.5, 1], [3, 2, 1, 0], [-1, 0.5, 0, 1], 0.9, ring=10, max_collisions=300,
                      events='none', temperature_csv=str(ours))
    cli(('--masses 1,2,1.5,1 --positions 3,2,1,0 --velocities -1,0.5,0,1 --restitution 0.9 --ring 10 '
         '--max-collisions 300 --events none --temperature-csv %s' % theirs).split())
    assert ours.read_text() == theirs.read_text()
    assert ours.read_text().count('\n') > 10


def test_lean_record_keeps_the_pairs_and_every_kth_state():
    """full_state_every=10: the per-body arrays at impact 1 and every 10th (NaN between),
    times and positions at every impact, as the full record has them (docs/cli.md)."""
    scene = dict(masses=[1e4, 1, math.inf], positions=[2, 1, 0], velocities=[-1, 0, 0])
    full = collision_lab.run(**scene)
    lean = collision_lab.run(**scene, full_state_every=10)
    assert lean.options['full_state_every'] == 10
    assert lean.summary['collision_count'] == full.summary['collision_count'] == 314
    index = lean.events['index']
    kept = (index == 1) | (index % 10 == 0)
    v_full, v_lean = full.events['velocities_after'], lean.events['velocities_after']
    assert np.array_equal(v_lean[kept], v_full[kept])
    assert np.isnan(v_lean[~kept]).all()
    assert np.array_equal(lean.events['time'], full.events['time'])
    assert np.array_equal(lean.events['position'], full.events['position'])


def test_the_cap_is_said_when_it_decides():
    """A run the cap leaves unsimulated, or cuts short, warns naming max_collisions and
    simulate_to_cap; a run within the cap does not. (Failed before: 314,159,265 collisions,
    0 events, silently.)"""
    with pytest.warns(collision_lab.CapWarning, match=r'314,159,265 collisions, more than max_collisions=10,000,000'):
        over = collision_lab.run([1e16, 1, INF], [2, 1, 0], [-1, 0, 0])
    assert not over.summary['simulated'] and over.summary['collision_count'] == 314159265
    with pytest.warns(collision_lab.CapWarning, match=r'stopped at max_collisions=50 \(truncated\) of the 314'):
        cut = collision_lab.run([1e4, 1, INF], [2, 1, 0], [-1, 0, 0], max_collisions=50, simulate_to_cap=True)
    assert cut.summary['collision_count'] == 50 and len(cut.events['time']) == 50
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        assert collision_lab.run([100, 1, INF], [2, 1, 0], [-1, 0, 0]).summary['collision_count'] == 31
        collision_lab.run([1e16, 1, INF], [2, 1, 0], [-1, 0, 0], mode='predict')
    from collision_lab import plot
    with pytest.raises(ValueError, match='simulate_to_cap=True'):
        plot.steps(over)


def test_a_run_shows_itself_in_a_notebook():
    """Run._repr_html_: the bodies with units, the model and why, the counts."""
    html = collision_lab.run([100, 1, INF], [2, 1, 0], [-1, 0, 0])._repr_html_()
    assert 'three_body_rotation' in html and 'mass [kg]' in html and 'v [m/s]' in html
    assert '<td>wall</td>' in html
    assert '<th style="text-align:left">collisions</th><td>31</td>' in html
    big = collision_lab.run(np.ones(20), np.arange(20)[::-1] * 1.0, np.zeros(20))._repr_html_()
    assert '20 bodies in all' in big and big.count('<tr><td>') == 12


def test_events_that_outgrow_memory_stop_the_run_and_say_what_to_ask_for():
    # The pi billiard at M/m = 1e10: 314,159 impacts, its events more than a 1 MiB budget.
    from collision_lab import _core, _run
    job = _run.core_job([1e10, 1, INF], [2, 1, 0], [-1, 0, 0])
    job['events_memory'] = 1 << 20
    with pytest.raises(MemoryError, match="events='first:N' or 'none'"):
        _run.result_of(_core.run(job)[0])
    job.update(events='none')
    report, events = _run.result_of(_core.run(job)[0])
    assert report['summary']['collision_count'] == 314159 and len(events['time']) == 0
