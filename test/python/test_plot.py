"""collision_lab.plot: the views' colours, worldlines to the run's end (cut at a ring's seam),
and T(t) with Haff's fit equal to the CLI's --temperature-csv (the C++ reference)."""
import math
import subprocess

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import collision_lab as cl  # noqa: E402
from collision_lab import plot  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close('all')


def test_colours_palette_by_index_walls_grey():
    run = cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0])
    # docs/web.md: A red (#f24040), B green (#40cc4d); a wall grey (#999999).
    assert [plot.hex_colour(c) for c in plot.body_colours(run)] == ['#f24040', '#40cc4d', '#999999']


def test_colours_beyond_ten_bodies_by_start_velocity():
    v = [-2, 0, 2, 1, -1, 0.5, 0, 0, 0, 0, 0, 0]
    x = [11.0, 10.1, 8.7, 7.9, 6.6, 5.2, 4.3, 3.1, 2.6, 1.4, 0.9, 0.0]
    run = cl.run([1] * 12, x, v, events='none')
    colours = plot.body_colours(run)
    assert colours[0] == pytest.approx((0.2, 0.4, 1.0))  # deepest left: blue
    assert colours[1] == pytest.approx((0.62, 0.42, 0.72))  # at rest: purple
    assert colours[2] == pytest.approx((1.0, 0.2, 0.15))  # deepest right: red
    assert colours[3] == pytest.approx(((0.62 + 1.0) / 2, (0.42 + 0.2) / 2, (0.72 + 0.15) / 2))


def test_steps_title_and_closed_form():
    run = cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0])
    ax = plot.steps(run)
    assert 'three_body_rotation' in ax.get_title() and '31 collisions' in ax.get_title()
    assert ax.get_xlabel().startswith('impact number') and '[m/s]' in ax.get_ylabel()


def test_worldlines_reach_the_runs_end():
    run = cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0])
    ax = plot.xt(run)
    end = 1.25 * run.events['time'][-1]
    lines = [line for line in ax.get_lines() if line.get_label() in ('A', 'B', 'C (wall)')]
    assert len(lines) == 3
    for line in lines:
        assert line.get_ydata()[-1] == pytest.approx(end)
    # A leaves at its final velocity: its line ends where free flight takes it.
    a = lines[0]
    v_a = run.events['velocities_after'][-1][0]
    x_a = run.events['positions'][-1][0] + v_a * (end - run.events['time'][-1])
    assert a.get_xdata()[-1] == pytest.approx(x_a)


def test_ring_worldlines_cut_at_the_seam():
    # One body at 1 m/s on a ring of 1 m with a partner far behind: crosses the seam often.
    run = cl.run([1, 1], [0.5, 0.25], [1, 0], ring=1.0, max_collisions=20)
    ax = plot.xt(run)
    xs = np.concatenate([line.get_xdata() for line in ax.get_lines()])
    assert xs.min() >= 0 and xs.max() <= 1.0
    for line in ax.get_lines():
        x, t = line.get_xdata(), line.get_ydata()
        # No jump across the diagram: every piece moves at most at the largest speed, 1 m/s.
        assert np.all(np.abs(np.diff(x)) <= 1.0 * np.diff(t) + 1e-12), 'a line crosses the diagram'


def test_ring_segments_split_at_every_crossing():
    pieces = plot.ring_segments(np.array([0.0, 3.0]), np.array([0.5, 3.5]), 1.0)
    assert len(pieces) == 4
    assert [p[1][0] for p in pieces] == pytest.approx([0.5, 0.0, 0.0, 0.0])
    assert [p[0][-1] for p in pieces] == pytest.approx([0.5, 1.5, 2.5, 3.0])


def test_granular_temperature_by_hand():
    # V = (1*1 + 3*(-1)) / 4 = -0.5; T = (1 * 1.5^2 + 3 * 0.5^2) / 2 = 1.5 (the wall is not counted).
    assert plot.granular_temperature([1, 3, math.inf], [1, -1, 0])[0] == pytest.approx(1.5)


def test_temperature_and_haff_fit_equal_the_clis(tmp_path, cli_path):
    rng = np.random.default_rng(7)
    n = 12
    masses, velocities = rng.uniform(1, 2, n), rng.uniform(-1, 1, n)
    positions = np.arange(n)[::-1] * 1.0
    run = cl.run(masses, positions, velocities, 0.9, ring=12.0, restitution_model='tc', tc=0.001, max_collisions=300,
                 simulate_to_cap=True)
    csv = tmp_path / 'T.csv'
    subprocess.run([cli_path, '--masses', ','.join(map(repr, masses)), '--positions', ','.join(map(repr, positions)),
                    '--velocities=' + ','.join(map(repr, velocities)), '--restitution', '0.9', '--ring', '12',
                    '--restitution-model', 'tc', '--tc', '0.001', '--max-collisions', '300', '--simulate-to-cap',
                    '--events', 'none', '--temperature-csv', str(csv)], check=True, capture_output=True)
    table, cli_fit = plot.read_temperature_csv(csv)
    impacts, t, T = plot.temperature_samples(run)
    assert list(impacts) == list(table['impacts'])
    assert t == pytest.approx(table['time_s'].to_numpy(), rel=1e-12)
    assert T == pytest.approx(table['temperature_J'].to_numpy(), rel=1e-9)
    kept = plot.thin_log_time(t)
    fit = plot.fit_haff(t[kept], T[kept])
    assert fit['samples'] == cli_fit['samples']
    for key in ('t0', 'tau', 'rms_ln_error'):
        assert fit[key] == pytest.approx(cli_fit[key], rel=1e-6)
    ax = plot.temperature(run)
    assert ax.get_xscale() == 'log' and ax.get_yscale() == 'log'
    assert any("Haff's law fitted" in text.get_text() for text in ax.get_legend().get_texts())


def test_no_haff_fit_for_what_is_not_a_cooling_gas():
    """The elastic pi billiard (3 bodies) and an elastic gas get no fit, and the legend says
    why. (Failed before: Haff's law was fitted to the pi billiard.)"""
    pi = cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0])
    texts = [t.get_text() for t in plot.temperature(pi).get_legend().get_texts()]
    assert not any("Haff's law fitted" in t for t in texts)
    assert any('2 bodies are not a gas' in t for t in texts), texts
    rng = np.random.default_rng(3)
    elastic = cl.run(rng.uniform(1, 2, 12), np.arange(12)[::-1] * 1.0, rng.uniform(-1, 1, 12), ring=12.0,
                     max_collisions=300, simulate_to_cap=True)
    texts = [t.get_text() for t in plot.temperature(elastic).get_legend().get_texts()]
    assert any('an elastic gas does not cool' in t for t in texts), texts


def test_plots_need_events():
    run = cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0], events='none')
    with pytest.raises(ValueError, match="events='all'"):
        plot.steps(run)
