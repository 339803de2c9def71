"""read_bag streams a bag's CollisionEvent messages into columns (issue 47): the columns are
those of the per-event records it built before (events_from_records of each message as the
CLI's JSON event, bag_reference.event_record), key for key, dtype for dtype and bit for bit, for scenes of
at most 64 bodies; above 64 bodies the per-body arrays are run()'s read-only view of one NaN.
No node is needed here: the messages are made from run()'s events, field for field as
collision_lab_node fills CollisionEvent (docs/messages.md). The bags the node records are
read in test_read_bag_large.py and read_bag_rostest.py."""
from types import SimpleNamespace

import numpy as np
import pytest

import collision_lab
from bag_reference import event_record, run_quietly
from collision_lab._bag import _EventColumns
from collision_lab._run import events_from_records

INF = float('inf')
_BODY = ('positions', 'velocities_before', 'velocities_after', 'energy_transfer', 'kinetic_energy_after')
_MODEL = ('predicted_velocities_after', 'paper_velocities_after', 'predicted_energy_transfer',
          'paper_energy_transfer')


def messages(run):
    """run()'s events as CollisionEvent messages: tuples as genpy gives fixed arrays, lists
    for the variable ones, empty where the record has no full state (NaN rows, or above 64
    bodies)."""
    e = run.events
    out = []
    for j in range(len(e['time'])):
        fields = dict(kind=0 if e['kind'][j] == 'impact' else 1, index=int(e['index'][j]),
                      pair_index=int(e['pair_index'][j]), time=float(e['time'][j]),
                      position=float(e['position'][j]), restitution=float(e['restitution'][j]),
                      first_moved=int(e['first_moved'][j]), last_moved=int(e['last_moved'][j]),
                      cluster_impact=bool(e['cluster_impact'][j]), energy_lost=float(e['energy_lost'][j]),
                      total_energy=float(e['total_energy'][j]), total_momentum=float(e['total_momentum'][j]),
                      uncertified=list(e['uncertified'][j]))
        for key in ('pair_velocities_before', 'pair_velocities_after', 'pair_energy_transfer'):
            fields[key] = tuple(float(x) for x in e[key][j])
        for key in _BODY + _MODEL:
            row = e[key][j] if key in e else []
            fields[key] = [] if len(row) == 0 or np.isnan(row).all() else [float(x) for x in row]
        out.append(SimpleNamespace(**fields))
    return out


def streamed(msgs, bodies):
    columns = _EventColumns(bodies)
    for msg in msgs:
        columns.add(msg)
    return columns.arrays()


def assert_same_columns(ours, theirs):
    """The same keys in the same order, dtypes, shapes and values bit for bit."""
    assert list(ours) == list(theirs)
    for key in theirs:
        assert ours[key].dtype == theirs[key].dtype, key
        assert ours[key].shape == theirs[key].shape, key
        if theirs[key].dtype.kind == 'f':
            assert ours[key].tobytes() == theirs[key].tobytes(), key
        else:
            assert ours[key].tolist() == theirs[key].tolist(), key


SCENES = {
    'pi': dict(masses=[100, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0]),
    'collapse': dict(masses=[1, 1, 1], positions=[2, 1, 0], velocities=[-1, 0, 0], restitution=0.05),
    'lean_engine': dict(masses=[1, 2, 3, 4, 5], positions=[4, 3, 2, 1, 0], velocities=[-1, 0.5, 0, 0.2, 1],
                        restitution=[0.9, 0.8, 1.0, 0.7], full_state_every=3),
    'ring_seam': dict(masses=[1, 2, 3, 1.5, 1], positions=[4, 3, 2, 1, 0], velocities=[-1, 0.5, 0, 0.2, 1],
                      ring=10, max_collisions=200),
    'sticky': dict(masses=[1, 2, 3, 4], positions=[3, 2, 1, 0], velocities=[-1, 0, 0, 1], restitution=0.0),
    'sixty_four': dict(masses=[1.0] * 64, positions=list(range(64, 0, -1)),
                       velocities=[(-1.0) ** i for i in range(64)]),
    'seventy': dict(masses=[1.0 + (i % 3) for i in range(70)], positions=list(range(70, 0, -1)),
                    velocities=[-1.0] + [0.0] * 68 + [1.0]),
    'no_impacts': dict(masses=[1, 1], positions=[1, 0], velocities=[1, -1]),
}


@pytest.mark.parametrize('name', list(SCENES))
def test_streamed_columns_are_the_records_columns(name):
    run = run_quietly(**SCENES[name])
    msgs = messages(run)
    bodies = len(run.masses)
    reference = events_from_records([event_record(m) for m in msgs], bodies)
    ours = streamed(msgs, bodies)
    assert_same_columns(ours, reference)



def test_non_finite_values_are_nan_as_in_the_json_and_an_inf_time_stays_and_short_rows_are_padded():
    run = collision_lab.run(**SCENES['pi'])
    msgs = messages(run)
    msgs[0].restitution = INF
    msgs[1].total_energy = -INF
    msgs[2].pair_velocities_after = (INF, 1.0)
    msgs[3].velocities_after = [1.0, INF, float('nan')]
    msgs[4].time = INF
    msgs[5].positions = [1.5, -0.0]  # shorter than the bodies: NaN after it, as before
    msgs[6].uncertified = ['positions']
    msgs[0].kinetic_energy_after = []  # NaN before the first row of an array
    reference = events_from_records([event_record(m) for m in msgs], 3)
    ours = streamed(msgs, 3)
    assert_same_columns(ours, reference)
    assert np.isnan(ours['restitution'][0]) and np.isnan(ours['total_energy'][1])
    assert np.isnan(ours['pair_velocities_after'][2, 0]) and ours['pair_velocities_after'][2, 1] == 1.0
    assert ours['time'][4] == INF
    assert ours['positions'][5].tobytes() == np.array([1.5, -0.0, np.nan]).tobytes()
    # A row longer than the bodies is refused, as before.
    msgs[7].velocities_before = [1.0, 2.0, 3.0, 4.0]
    with pytest.raises(ValueError):
        events_from_records([event_record(m) for m in msgs], 3)
    with pytest.raises(ValueError):
        streamed(msgs, 3)
    assert ours['uncertified'][6] == ('positions',)
    assert np.isnan(ours['kinetic_energy_after'][0]).all() and not np.isnan(ours['kinetic_energy_after'][1:]).any()


def test_above_64_bodies_the_per_body_arrays_hold_no_memory():
    # As run() gives them: the per-body arrays a read-only view of one NaN (strides 0); the
    # pair fields the run's, bit for bit.
    run = collision_lab.run(**SCENES['seventy'])
    ours = streamed(messages(run), 70)
    for key in _BODY:
        assert ours[key].shape == (len(run.events['time']), 70) and ours[key].strides == (0, 0), key
        assert not ours[key].flags.writeable and np.isnan(ours[key]).all()
        assert run.events[key].strides == (0, 0)
    assert not set(_MODEL) & set(ours)
    for key in ('pair_velocities_before', 'pair_velocities_after', 'pair_energy_transfer', 'time', 'position'):
        assert ours[key].tobytes() == run.events[key].tobytes(), key
