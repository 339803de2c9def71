"""Run.state_at: the bodies' state after an event or at any time, rebuilt from the pair
fields every record carries (no dense events x bodies array needed)."""
import numpy as np
import pytest

import collision_lab

INF = float('inf')


def pi_run(**options):
    return collision_lab.run([100, 1, INF], [2, 1, 0], [-1, 0, 0], **options)


def test_a_lean_record_gives_every_state_of_the_full_one():
    # full_state_every=10: only impacts 1, 10, 20, 30 carry every body; state_at rebuilds
    # the others, and they equal the full record's: velocities bit for bit, positions to
    # rounding (the full record's are the engine's, these are flown from the contacts).
    full, lean = pi_run(), pi_run(full_state_every=10)
    assert np.isnan(lean.events['velocities_after'][1]).all()
    for k in range(1, 32):
        x, v = lean.state_at(k)
        assert np.array_equal(v, full.events['velocities_after'][k - 1]), k
        assert np.allclose(x, full.events['positions'][k - 1], rtol=0, atol=4e-15), k


def test_states_at_times_by_hand():
    # A (100 kg, -1 m/s from 2 m) meets B (at rest at 1 m) at t = 1 s, x = 1 m; before
    # that only A moves: at t = 0.5 s it is at 1.5 m.
    run = pi_run()
    x, v = run.state_at(t=0.5)
    assert list(x) == [1.5, 1, 0] and list(v) == [-1, 0, 0]
    xs, vs = run.state_at(t=[0, 0.5, 1.0])
    assert xs.shape == (3, 3) and list(xs[2]) == [1, 1, 0]
    assert list(vs[2]) == list(run.events['velocities_after'][0])  # just after the impact
    assert list(run.state_at(0)[0]) == [2, 1, 0]
    # After the last impact every body flies freely: the final velocities.
    assert list(run.state_at(t=1e6)[1]) == list(run.summary['final_velocities'])


def test_a_ring_wraps_its_positions():
    # Two bodies on a ring of 4 m: B (at 1 m, +1 m/s) meets A (at 3 m, at rest) across
    # nothing: they approach on the short side; every state stays in [0, 4).
    with pytest.warns(collision_lab.CapWarning):  # endless: it stops at its cap
        run = collision_lab.run([1, 1], [3, 1], [0, 1], ring=4, max_collisions=50, simulate_to_cap=True)
    assert 'AB' in set(run.events['pair']) and len(set(run.events['pair'])) == 2  # the seam pair too
    xs, _ = run.state_at(t=np.linspace(0, 40, 81))
    assert np.all((xs >= 0) & (xs < 4))


def test_bad_arguments_are_refused():
    run = pi_run()
    with pytest.raises(TypeError):
        run.state_at()
    with pytest.raises(TypeError):
        run.state_at(1, t=1.0)
    with pytest.raises(ValueError):
        run.state_at(32)
    with pytest.raises(ValueError):
        run.state_at(t=-1)


def test_more_than_64_bodies_hold_no_dense_per_body_arrays():
    # 200 equal masses, every other one moving left: the record carries the pair fields only,
    # and the per-body arrays are one NaN seen through a view (no events x bodies memory);
    # state_at gives every body's velocity. Equal masses only exchange velocities: the end's
    # are the start's, rearranged, and state_at's are the summary's.
    n = 200
    v0 = np.where(np.arange(n) % 2 == 0, -1.0, 1.0)
    run = collision_lab.run([1.0] * n, [float(x) for x in range(n, 0, -1)], v0)
    per_body = run.events['velocities_after']
    assert per_body.shape == (len(run.events['time']), n) and per_body.strides == (0, 0)
    assert np.isnan(per_body).all()
    _, v = run.state_at(len(run.events['time']))
    assert sorted(v) == sorted(v0)
    assert list(v) == list(run.summary['final_velocities'])


def test_no_state_past_an_incomplete_record():
    # events='first:5' records 5 of the 31 impacts: after the fifth nothing is known, and
    # flying on would put B behind the wall.
    run = pi_run(events='first:5')
    last = run.events['time'][-1]
    run.state_at(t=last)  # up to the record's end: known
    with pytest.raises(ValueError, match='record ends'):
        run.state_at(t=last + 1)
    # The whole run recorded: after its last impact every body flies freely.
    complete = pi_run()
    assert list(complete.state_at(t=complete.events['time'][-1] + 1)[1]) == list(complete.summary['final_velocities'])


def test_times_in_any_order_are_the_states_at_each():
    run = pi_run()
    times = np.array([3.0, 0.5, 4.5, 1.0, 0.0])
    xs, vs = run.state_at(t=times)
    for row, time in enumerate(times):
        x, v = run.state_at(t=float(time))
        assert list(xs[row]) == list(x) and list(vs[row]) == list(v), time


def test_a_tables_asked_for_bodies_are_state_at_for_every_event():
    # to_pandas(bodies=...) rebuilds the columns of the bodies named, in one pass: after
    # event k they are state_at(k); of a lean record, the full record's velocities bit for
    # bit at every event, as state_at's.
    full, lean = pi_run(), pi_run(full_state_every=10)
    table = lean.to_pandas(bodies='all')
    assert [c for c in table.columns if c[:2] in ('v_', 'x_')] == ['v_A', 'v_B', 'v_C', 'x_A', 'x_B', 'x_C']
    for i, name in enumerate(lean.names):
        assert table['v_' + name].to_numpy().tobytes() == full.events['velocities_after'][:, i].tobytes(), name
        np.testing.assert_allclose(table['x_' + name], full.events['positions'][:, i], rtol=0, atol=4e-15)
    # Above 64 bodies: none by default, and those asked for by name or index.
    n = 200
    v0 = np.where(np.arange(n) % 2 == 0, -1.0, 1.0)
    many = collision_lab.run([1.0] * n, [float(x) for x in range(n, 0, -1)], v0)
    assert not [c for c in many.to_pandas().columns if c[:2] in ('v_', 'x_')]
    chosen = many.to_pandas(bodies=['#199', 0])
    assert list(chosen.columns[-4:]) == ['v_#199', 'v_A', 'x_#199', 'x_A']
    for k in (1, len(chosen) // 2, len(chosen)):
        x, v = many.state_at(k)
        assert (chosen['v_#199'][k - 1], chosen['v_A'][k - 1]) == (v[199], v[0]), k
        assert (chosen['x_#199'][k - 1], chosen['x_A'][k - 1]) == (x[199], x[0]), k
    # Equal masses exchange velocities: A (rightmost, -1 m/s first) ends with the fastest
    # rightward velocity, +1 m/s; the leftmost body with -1 m/s.
    assert (chosen['v_A'].iloc[-1], chosen['v_#199'].iloc[-1]) == (1.0, -1.0)
    with pytest.raises(ValueError, match='not a body'):
        many.to_pandas(bodies=[200])
    with pytest.raises(ValueError, match='not a body'):
        many.to_pandas(bodies=[True])
