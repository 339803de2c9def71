"""read_bag on bags of many bodies that collision_lab_node records (issue 47: "read_bag
streams a large bag, and gives every body's velocity"): above CollisionEvent's
FULL_STATE_MAX_BODIES (64) the messages carry the pair's fields only; read_bag keeps no
events x bodies array for them, and state_at gives every body's state, as for run()'s runs.
The bags come from the record_bag fixture (conftest.py: two nodes under roslaunch)."""
import os
import shutil
import tracemalloc

import numpy as np
import pytest

import collision_lab
from bag_reference import event_record, run_quietly

PER_BODY = ('positions', 'velocities_before', 'velocities_after', 'energy_transfer', 'kinetic_energy_after')
PAIR = ('pair_velocities_before', 'pair_velocities_after', 'pair_energy_transfer')


def ring(n, length, masses, restitution=1.0, cap=20_000, seed=1, **options):
    """n bodies evenly spaced on a ring of `length` m, velocities uniform in [-1, 1] m/s (seeded)."""
    gap = length / n
    return dict(masses=masses, positions=[length - gap * (i + 0.5) for i in range(n)],
                velocities=np.random.default_rng(seed).uniform(-1, 1, n).tolist(), restitution=restitution,
                ring=float(length), max_collisions=cap, **options)


# 400 bodies of three masses, elastic: past the 64 of the full state. 40 bodies, e = 0.9
# with the TC model: within it, so its messages carry every body's state.
MANY = ring(400, 800.0, [1.0 + 0.5 * (i % 3) for i in range(400)])
FEW = ring(40, 80.0, [1.0 + 0.25 * (i % 5) for i in range(40)], restitution=0.9, cap=3000,
           restitution_model='tc', tc=1e-3, seed=2)



@pytest.fixture(scope='module')
def many_path(record_bag):
    return record_bag('many_ring', MANY)


@pytest.fixture(scope='module')
def few_path(record_bag):
    return record_bag('few_ring', FEW)


@pytest.fixture(scope='module')
def many(many_path):
    return collision_lab.read_bag(many_path)


def as_before(path):
    """The event columns as read_bag built them before it streamed (issue 47): every message
    kept, each made the CLI's JSON event, then events_from_records."""
    import rosbag
    from collision_lab._run import events_from_records
    with rosbag.Bag(path) as bag:
        masses = [m for _, m, _ in bag.read_messages() if m._type.endswith('/InitialConditions')][0].masses
        messages = [m for _, m, _ in bag.read_messages() if m._type.endswith('/CollisionEvent')]
    return events_from_records([event_record(m) for m in messages], len(masses))


def assert_as_before(events, before):
    """The same keys in the same order, dtypes, shapes and values bit for bit."""
    assert list(events) == list(before)
    for key, values in before.items():
        assert events[key].dtype == values.dtype and events[key].shape == values.shape, key
        if values.dtype.kind == 'f':
            assert events[key].tobytes() == values.tobytes(), key
        else:
            assert events[key].tolist() == values.tolist(), key


def sampled(count, samples=9):
    return sorted({int(k) for k in np.linspace(0, count, samples)})


def test_a_bag_of_400_bodies_has_the_runs_pair_columns_and_no_dense_arrays(many_path, many):
    count = len(many.events['time'])
    assert count == many.summary['collision_count'] == 20_000 and len(many.masses) == 400
    again = run_quietly(**many.scene)
    assert again.summary['collision_count'] == count
    for key in PAIR + ('time', 'position', 'index', 'pair_index', 'first_moved', 'last_moved'):
        assert many.events[key].tobytes() == again.events[key].tobytes(), key
    assert many.events['pair'].tolist() == again.events['pair'].tolist()
    # The per-body arrays: as run()'s, a read-only view of one NaN of shape events x bodies.
    for key in PER_BODY:
        array = many.events[key]
        assert array.shape == (count, 400) and array.strides == (0, 0) and not array.flags.writeable, key
        assert array.base is not None and array.base.size == 1
        assert again.events[key].strides == (0, 0)
    # As read_bag gave them before it streamed: the same values (NaN, then in dense arrays).
    assert_as_before(many.events, as_before(many_path))


def test_every_bodys_state_of_a_bag_of_400_bodies(many):
    count = len(many.events['time'])
    again = run_quietly(**many.scene)
    m = many.masses
    v0 = many.initial_velocities
    p0, e0 = float(np.sum(m * v0)), float(np.sum(m * v0 ** 2) / 2)
    for k in sampled(count):
        x, v = many.state_at(k)
        x_run, v_run = again.state_at(k)
        assert v.tobytes() == v_run.tobytes() and x.tobytes() == x_run.tobytes(), k
        # Elastic impacts on a ring (no walls): momentum and kinetic energy conserved, to rounding.
        assert abs(np.sum(m * v) - p0) <= 1e-12 * np.sum(m * np.abs(v0)), k
        assert abs(np.sum(m * v ** 2) / 2 - e0) <= 1e-13 * e0, k
        assert np.all((x >= 0) & (x < 800.0)), k
    # After the last event: the final velocities that RunSummary recorded from the engine's
    # own state, bit for bit.
    _, v = many.state_at(count)
    assert [float(x).hex() for x in v] == [float(x).hex() for x in many.summary['final_velocities']]
    # At a time: the state after the events up to it, as run()'s.
    t = float(many.events['time'][count // 2])
    for ours, theirs in zip(many.state_at(t=t), again.state_at(t=t)):
        assert ours.tobytes() == theirs.tobytes()


def test_reading_a_bag_of_400_bodies_holds_no_events_x_bodies_memory(many_path, many):
    many.to_pandas()  # pandas imported, and what it imports on first use
    count, bodies = len(many.events['time']), len(many.masses)
    tracemalloc.start()
    try:
        bag = collision_lab.read_bag(many_path)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.reset_peak()
        before, _ = tracemalloc.get_traced_memory()
        table = bag.to_pandas()
        _, table_peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # One events x bodies array of doubles: 64 MB (the record of old held five, and a dict
    # of lists per event). The columns take about 200 bytes an event, rosbag's index of the
    # bag about as much while it is open.
    dense = count * bodies * 8
    assert peak < dense / 5 and peak < 1000 * count, '%.1f MB' % (peak / 1e6)
    assert table_peak - before < dense / 5, '%.1f MB' % ((table_peak - before) / 1e6)
    assert len(table) == count
    assert len(bag.events['time']) == count


def test_a_large_bags_table_leaves_out_the_bodies_unless_asked(many):
    again = run_quietly(**many.scene)
    table = many.to_pandas()
    # Above 64 bodies no v_/x_ columns by default, for run()'s runs and read_bag's alike.
    assert list(table.columns) == list(again.to_pandas().columns)
    assert not [c for c in table.columns if c.startswith(('v_', 'x_'))]
    assert set(table.attrs['units']) == {'time', 'position', 'energy_lost', 'total_energy', 'total_momentum'}
    assert table['time'].to_numpy().tobytes() == many.events['time'].tobytes()
    # Asked for: those bodies' columns, each row the state after that event.
    chosen = many.to_pandas(bodies=['A', '#250', 7])
    assert [c for c in chosen.columns if c.startswith(('v_', 'x_'))] == ['v_A', 'v_#250', 'v_H', 'x_A', 'x_#250',
                                                                        'x_H']
    assert chosen.attrs['units']['v_#250'] == 'm/s' and chosen.attrs['units']['x_H'] == 'm'
    for k in sampled(len(table))[1:]:
        x, v = many.state_at(k)
        row = chosen.iloc[k - 1]
        assert [row['v_A'], row['v_#250'], row['v_H']] == [v[0], v[250], v[7]], k
        assert [row['x_A'], row['x_#250'], row['x_H']] == [x[0], x[250], x[7]], k
    run_chosen = again.to_pandas(bodies=['A', '#250', 7])
    assert chosen['v_#250'].to_numpy().tobytes() == run_chosen['v_#250'].to_numpy().tobytes()
    with pytest.raises(ValueError, match='not a body'):
        many.to_pandas(bodies=['#400'])


def test_a_bag_of_40_bodies_state_at_is_its_messages_full_state(few_path):
    bag = collision_lab.read_bag(few_path)
    count = len(bag.events['time'])
    assert count == 3000 and len(bag.masses) == 40
    assert_as_before(bag.events, as_before(few_path))
    velocities_after = bag.events['velocities_after']
    assert velocities_after.strides != (0, 0) and not np.isnan(velocities_after).any()
    p0 = float(np.sum(bag.masses * bag.initial_velocities))
    for k in sampled(count, 31)[1:]:
        x, v = bag.state_at(k)
        # Rebuilt from the pair fields, it is the state each message carries for every body:
        # the velocities bit for bit, the positions to rounding (flown from the last contact).
        assert v.tobytes() == velocities_after[k - 1].tobytes(), k
        np.testing.assert_allclose(x, bag.events['positions'][k - 1], rtol=0, atol=1e-12, err_msg=str(k))
        # A ring has no walls: the TC model's inelastic impacts keep the momentum.
        assert abs(np.sum(bag.masses * v) - p0) <= 1e-12 * np.sum(bag.masses * np.abs(bag.initial_velocities))
    # Up to 64 bodies the table has every body's columns from the messages; asked for, the
    # rebuilt ones, the same velocities.
    table, rebuilt = bag.to_pandas(), bag.to_pandas(bodies='all')
    assert list(table.columns) == list(rebuilt.columns)
    assert sum(c.startswith('v_') for c in table.columns) == 40
    for name in bag.names:
        assert table['v_' + name].to_numpy().tobytes() == rebuilt['v_' + name].to_numpy().tobytes(), name
        np.testing.assert_allclose(table['x_' + name], rebuilt['x_' + name], rtol=0, atol=1e-12)


def test_python_md_read_bag_example_runs_as_written(many_path, many, tmp_path, monkeypatch):
    """docs/python.md's read_bag example, run as written on a home folder whose node bag
    folder holds the 400-body bag (the example reads the newest bag there)."""
    import re
    folder = tmp_path / '.ros' / 'collision_lab' / 'runs' / 'collision_lab'
    folder.mkdir(parents=True)
    shutil.copy(many_path, folder / 'many_ring.bag')
    monkeypatch.setenv('HOME', str(tmp_path))
    docs = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'docs', 'python.md')).read()
    section = docs[docs.index('## A run the node recorded: `collision_lab.read_bag`'):]
    code = re.search(r'```python\n(.*?)```', section, re.S).group(1)
    space = {'collision_lab': collision_lab}
    exec(code, space)
    bag = space['bag']
    assert len(bag.masses) == 400
    assert bag.events['time'].tobytes() == many.events['time'].tobytes()
    assert space['velocities'].shape == (400,)
    assert list(space['velocities']) == list(bag.summary['final_velocities'])
