"""Round trips (issue 47): a Run's scene goes back into run(**scene) and runs the same run,
for run() and for read_bag() of the bags collision_lab_node records; and run(), sweep()
and read_bag() give one set of summary keys for every model (read_bag adds exactly run_id,
student and bag_path)."""

import numpy as np
import pytest

import collision_lab
from bag_reference import run_quietly

INF = float('inf')

# Written out here, not taken from the module: run()'s keyword arguments but temperature_csv.
SCENE_KEYS = ['name', 'masses', 'positions', 'velocities', 'restitution', 'ring', 'restitution_model', 'tc',
              'elastic_below', 'viscoelastic_speed', 'max_collisions', 'simulate_to_cap', 'mode', 'events',
              'full_state_every']
# The one set of summary keys: the CLI's three-body report's and its scene report's together.
SUMMARY_KEYS = {'model', 'model_reason', 'collision_count', 'simulated', 'truncated', 'cancelled',
                'truncation_reason', 'stop_reason', 'stop_message', 'predicted_collision_count',
                'predicted_infinite', 'count_formula', 'matches_prediction', 'max_prediction_error', 'final_time',
                'time_beyond_range', 'energy_lost', 'energy_relative_drift', 'momentum_relative_drift',
                'compute_time_s', 'collapsed', 'collapse_time', 'collapse_position', 'cluster_impacts',
                'rule_elastic_impacts', 'critical_restitution', 'spiral_angle', 'uncertified_values',
                'multiple_collision', 'escalation', 'final_velocities', 'predicted_final_velocities',
                'paper_predicted_collision_count', 'max_possible_collision_count', 'predicted_first_pair', 'theta',
                'alpha', 'omega', 'psi', 'paper_phi_bc'}
ESCALATION_KEYS = {'decisions', 'refinements', 'high_precision', 'exact_rational', 'replayed_impacts'}
BAG_ONLY_KEYS = {'run_id', 'student', 'bag_path'}

# (name, node, scene as run()'s keyword arguments, model, collision count where physics says it)
RECORDED = [
    ('pi', 'plain', dict(masses=[100, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0]), 'three_body_rotation', 31),
    ('two_body', 'plain', dict(masses=[3, 1], positions=[1, 0], velocities=[-1, 1]), 'two_body', 1),
    # Equal masses exchange velocities: A hands -1 m/s to B, B to C.
    ('equal_masses', 'plain', dict(masses=[1, 1, 1], positions=[2, 1, 0], velocities=[-1, 0, 0]),
     'three_body_rotation', 2),
    ('ghosts', 'plain', dict(masses=[1, 1, 1, 1], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1]), 'ghosts', None),
    ('collapse', 'plain', dict(masses=[1, 1, 1], positions=[2, 1, 0], velocities=[-1, 0, 0], restitution=0.05),
     'three_body_spiral', 8),
    ('sticky', 'plain', dict(masses=[1, 2, 3, 4], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1], restitution=0.0),
     'sticky', None),
    ('engine', 'plain', dict(masses=[1, 2, 3, 4, 5], positions=[4, 3, 2, 1, 0], velocities=[-1, 0.5, 0, 0.2, 1],
                             restitution=[0.9, 0.8, 1.0, 0.7]), 'event_engine', None),
    ('gas_ring_tc', 'plain', dict(masses=[1, 2, 1.5, 1, 1.2, 1.1], positions=[5.5, 4.2, 3.1, 2, 1, 0.3],
                                  velocities=[-1, 0.5, 0, 1, -0.3, 0.2], restitution=0.9, ring=10.0,
                                  restitution_model='tc', tc=1e-3, max_collisions=500), 'event_engine', 500),
    ('threshold', 'plain', dict(masses=[1, 2, 3, 2], positions=[3, 2, 1, 0], velocities=[-1, 0.3, 0, 1],
                                restitution=0.5, restitution_model='threshold', elastic_below=0.4),
     'event_engine', None),
    ('viscoelastic', 'plain', dict(masses=[1, 2, 3, 2], positions=[3, 2, 1, 0], velocities=[-1, 0.3, 0, 1],
                                   restitution_model='viscoelastic', viscoelastic_speed=2.0), 'event_engine', None),
    # Over the cap: the model answers (314 for m_A = 10^4 m_B); with ~simulate_to_cap the first 50.
    ('over_cap', 'plain', dict(masses=[1e4, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0], max_collisions=50),
     'three_body_rotation', 314),
    ('to_cap', 'to_cap', dict(masses=[1e4, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0], max_collisions=50),
     'three_body_rotation', 50),
    # Two walls: endless; 1,000 impacts shown without simulate_to_cap, the cap with it.
    ('walls', 'plain', dict(masses=[INF, 1, INF], positions=[1, 0.5, 0], velocities=[0, 1, 0], max_collisions=2500),
     'two_walls_infinite', 1000),
    ('walls_to_cap', 'to_cap', dict(masses=[INF, 1, INF], positions=[1, 0.5, 0], velocities=[0, 1, 0],
                                    max_collisions=2500), 'two_walls_infinite', 2500),
    ('predict', 'plain', dict(masses=[1e4, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0], mode='predict'),
     'three_body_rotation', 314),
    ('summary_mode', 'plain', dict(masses=[1, 2, 3, 4, 5], positions=[4, 3, 2, 1, 0],
                                   velocities=[-1, 0.5, 0, 0.2, 1], mode='summary'), 'event_engine', None),
]
IDS = [r[0] for r in RECORDED]


def bits(values):
    """Each double's bits (-0.0 and 0.0 differ), None kept."""
    return None if values is None else [None if v is None else float(v).hex() for v in values]



@pytest.fixture(scope='module')
def bags(record_bag):
    """name -> the Run read back from the bag of that scene's node run."""
    return {name: collision_lab.read_bag(record_bag(name, scene, node)) for name, node, scene, _, _ in RECORDED}


@pytest.mark.parametrize('name,node,given,model,count', RECORDED, ids=IDS)
def test_a_bags_scene_runs_the_recorded_run_again(bags, name, node, given, model, count):
    bag = bags[name]
    scene = bag.scene
    assert list(scene) == SCENE_KEYS
    # The scene as it was sent, in run()'s terms.
    assert scene['masses'] == [float(m) for m in given['masses']]
    assert scene['velocities'] == [float(v) for v in given['velocities']]
    assert scene['restitution'] == given.get('restitution', 1.0)
    assert scene['ring'] == given.get('ring')
    assert scene['restitution_model'] == given.get('restitution_model', 'constant')
    for key in ('tc', 'elastic_below', 'viscoelastic_speed'):
        assert scene[key] == given.get(key), key
    assert scene['max_collisions'] == given.get('max_collisions', 10_000_000)
    assert scene['mode'] == given.get('mode', 'full')
    assert scene['events'] == ('all' if scene['mode'] == 'full' else 'none')
    assert scene['simulate_to_cap'] is (node == 'to_cap')
    assert scene['name'] == name
    # The same run: model, count and final velocities bit for bit, and the same events.
    again = run_quietly(**scene)
    assert bag.model == again.model == model
    assert bag.summary['collision_count'] == again.summary['collision_count']
    if count is not None:
        assert again.summary['collision_count'] == count
    assert bag.summary['simulated'] == again.summary['simulated']
    assert bag.summary['final_velocities'] and bits(again.summary['final_velocities']) == bits(
        bag.summary['final_velocities'])
    assert again.events['kind'].tolist() == bag.events['kind'].tolist()
    np.testing.assert_array_equal(again.events['time'], bag.events['time'])
    np.testing.assert_array_equal(again.events['velocities_after'], bag.events['velocities_after'])


def test_a_bags_events_table_is_a_runs_with_its_units(bags):
    bag, run = bags['engine'], collision_lab.run(**bags['engine'].scene)
    table = bag.to_pandas()
    assert list(table.columns) == list(run.to_pandas().columns)
    assert table.attrs['units'] == run.to_pandas().attrs['units']
    assert table.attrs['units']['v_E'] == 'm/s' and table.attrs['units']['total_momentum'] == 'kg m/s'


def test_simulate_to_cap_is_read_from_what_the_run_did(bags):
    """The bag does not record the node's ~simulate_to_cap; read_bag takes it from the
    summary. Without it the to_cap bags would not run again as recorded."""
    for name, recorded in (('to_cap', 50), ('walls_to_cap', 2500)):
        scene = dict(bags[name].scene, simulate_to_cap=False)
        assert run_quietly(**scene).summary['collision_count'] != recorded
    assert not bags['over_cap'].summary['simulated'] and not bags['over_cap'].scene['simulate_to_cap']
    with pytest.warns(collision_lab.CapWarning, match='more than max_collisions=50'):
        collision_lab.run(**bags['over_cap'].scene)


# Every model of test_run.py's scenes, and options that the scene must carry.
RUNS = [
    dict(masses=[1, 2, 3], positions=[2, 1, 0], velocities=[1, 0, -1]),
    dict(masses=[3, 1], positions=[1, 0], velocities=[-1, 1]),
    dict(masses=[100, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0]),
    dict(masses=[1, 1, 1], positions=[2, 1, 0], velocities=[-1, 0, 0], restitution=0.05),
    dict(masses=[1, 1, 1, 1], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1]),
    dict(masses=[1, 2, 3, 4], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1], restitution=0),
    dict(masses=[INF, 1, INF], positions=[1, 0.5, 0], velocities=[0, 1, 0]),
    dict(masses=[INF, 1, 2, INF], positions=[3, 2, 1, 0], velocities=[0, 1, -1, 0], restitution=0.5,
         max_collisions=200),
    dict(masses=[1, 2, 3, 1.5, 1], positions=[4, 3, 2, 1, 0], velocities=[-1, 0.5, 0, 0.2, 1], restitution=0.8,
         restitution_model='tc', tc=1e-3, ring=10, max_collisions=500),
    dict(masses=[1, 2, 3, 2], positions=[3, 2, 1, 0], velocities=[-1, 0.3, 0, 1], restitution=[0.5, 0.6, 0.7],
         restitution_model='threshold', elastic_below=0.4),
    dict(masses=np.array([1.0, 2.0, 3.0, 4.0]), positions=np.array([3.0, 2.0, 1.0, 0.0]),
         velocities=np.array([-1.0, 0.0, 0.0, 1.0]), events='first:3', simulate_to_cap=True, mode='summary',
         full_state_every=2, name='numpy'),
    dict(masses=[1e4, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0], mode='predict'),
    dict(masses=[1e4, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0], max_collisions=50, simulate_to_cap=True),
]


def without_wall_time(report):
    return dict(report, summary={k: v for k, v in report['summary'].items() if k != 'compute_time_s'})


@pytest.mark.parametrize('kwargs', RUNS, ids=[str(i) for i in range(len(RUNS))])
def test_a_runs_scene_runs_it_again(kwargs):
    first = run_quietly(**kwargs)
    assert list(first.scene) == SCENE_KEYS
    again = run_quietly(**first.scene)
    assert without_wall_time(again.report) == without_wall_time(first.report)
    assert again.scene == first.scene
    assert bits(again.summary['final_velocities']) == bits(first.summary['final_velocities'])
    # As a sweep's scene too: the same summary.
    row = collision_lab.sweep([first.scene], workers=1).iloc[0]
    assert row['collision_count'] == first.summary['collision_count']
    assert bits(row['final_velocities']) == bits(first.summary['final_velocities'])


def test_a_runs_scene_is_its_arguments_in_python_terms():
    run = collision_lab.run(np.array([100, 1, INF]), [2, 1, 0], (-1, 0, 0), restitution=[1, 1], name='pi')
    assert run.scene == {'name': 'pi', 'masses': [100.0, 1.0, INF], 'positions': [2.0, 1.0, 0.0],
                         'velocities': [-1.0, 0.0, 0.0], 'restitution': [1.0, 1.0], 'ring': None,
                         'restitution_model': 'constant', 'tc': None, 'elastic_below': None,
                         'viscoelastic_speed': None, 'max_collisions': 10_000_000, 'simulate_to_cap': False,
                         'mode': 'full', 'events': 'all', 'full_state_every': 1}
    assert all(type(x) is float for x in run.scene['masses'])
    # The CLI's descriptive scene stays in the report; the walls are named on the Run.
    assert run.report['scene']['walls'] == ['C'] and run.walls == ['C']


# Summary keys: one model per entry (three-body rotation, two-body, equal masses, sticky
# and its isotonic groups, the event engine, a gas), run, swept and recorded.
MODELS = ['pi', 'two_body', 'equal_masses', 'ghosts', 'collapse', 'sticky', 'engine', 'gas_ring_tc', 'walls',
          'predict']


def flattened(keys):
    return (set(keys) - {'escalation'}) | {'escalation.' + k for k in ESCALATION_KEYS}


@pytest.mark.parametrize('name', MODELS)
def test_run_sweep_and_read_bag_give_the_same_summary_keys(bags, name):
    given = next(scene for n, _, scene, _, _ in RECORDED if n == name)
    run = run_quietly(**given)
    assert set(run.summary) == SUMMARY_KEYS
    assert set(run.summary['escalation']) == ESCALATION_KEYS
    table = collision_lab.sweep([given], events='all')
    assert set(table.columns) == flattened(SUMMARY_KEYS) | {'error_reason', 'error_field', 'error_message'}
    bag = bags[name]
    assert set(bag.summary) - set(run.summary) == BAG_ONLY_KEYS
    assert set(run.summary) - set(bag.summary) == set()
    assert set(bag.summary['escalation']) == ESCALATION_KEYS
    # Values: where the CLI's report and the bag both give one, the same; where the CLI's
    # report had no key, the value run() fills in is the node's (or None).
    held = collision_lab._bag.BAG_SUMMARY_KEYS
    for key in held:
        if key == 'compute_time_s':
            continue
        if key in run.report['summary'] or run.summary[key] is not None:
            assert run.summary[key] == bag.summary[key], key
    assert run.summary['collapsed'] is bag.summary['collapsed']


def test_the_models_share_one_key_set_and_fills_say_what_the_model_decides():
    rotation = collision_lab.run([100, 1, INF], [2, 1, 0], [-1, 0, 0])
    assert 'collapsed' not in rotation.report['summary']  # the CLI's three-body report
    s = rotation.summary
    assert (s['collapsed'], s['collapse_time'], s['energy_lost'], s['cluster_impacts'], s['predicted_infinite']) == (
        False, None, 0.0, 0, False)
    with pytest.warns(collision_lab.CapWarning):
        engine = collision_lab.run([1, 2, 3, 4, 5], [4, 3, 2, 1, 0], [-1, 0.5, 0, 0.2, 1], max_collisions=3)
    assert 'cancelled' not in engine.report['summary']  # the CLI's scene report
    assert engine.summary['cancelled'] is False and engine.summary['truncated']
    assert engine.summary['truncation_reason'] == engine.summary['stop_message'] != ''
    assert engine.summary['theta'] is None
    assert list(rotation.summary) == list(engine.summary)


def test_a_bags_events_name_a_ring_seams_pair_as_run_does():
    # read_bag names each CollisionEvent's pair; across a ring's seam (last_moved below
    # pair_index) the pair is the last body and A ('EA'), as run() names it.
    from types import SimpleNamespace
    from collision_lab._bag import _EventColumns
    run = collision_lab.run([1, 2, 3, 1.5, 1], [4, 3, 2, 1, 0], [-1, 0.5, 0, 0.2, 1], ring=10, max_collisions=100)
    e = run.events
    seams = [j for j in range(len(e['time'])) if e['kind'][j] == 'impact' and e['last_moved'][j] < e['pair_index'][j]]
    assert seams and e['pair'][seams[0]] == 'EA'
    columns = _EventColumns(5)
    for j in range(len(e['time'])):
        empty = []
        msg = SimpleNamespace(kind=0 if e['kind'][j] == 'impact' else 1, index=int(e['index'][j]),
                              pair_index=int(e['pair_index'][j]), time=float(e['time'][j]),
                              position=float(e['position'][j]), restitution=float(e['restitution'][j]),
                              first_moved=int(e['first_moved'][j]), last_moved=int(e['last_moved'][j]),
                              cluster_impact=bool(e['cluster_impact'][j]),
                              pair_velocities_before=e['pair_velocities_before'][j],
                              pair_velocities_after=e['pair_velocities_after'][j],
                              pair_energy_transfer=e['pair_energy_transfer'][j], energy_lost=0.0, total_energy=0.0,
                              total_momentum=0.0, positions=empty, velocities_before=empty, velocities_after=empty,
                              energy_transfer=empty, kinetic_energy_after=empty, predicted_velocities_after=empty,
                              paper_velocities_after=empty, predicted_energy_transfer=empty, paper_energy_transfer=empty)
        columns.add(msg)
    assert columns.arrays()['pair'].tolist() == e['pair'].tolist()
