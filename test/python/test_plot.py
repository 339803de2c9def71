"""collision_lab.plot: the views' colours, worldlines to the run's end (cut at a ring's seam),
and T(t) with Haff's fit equal to the CLI's --temperature-csv (the C++ reference)."""
import math
import os
import re
import subprocess

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import collision_lab as cl  # noqa: E402
from collision_lab import plot  # noqa: E402


def legend_texts(ax):
    """The legend's entries, each on one line (legends wrap long labels)."""
    return [' '.join(text.get_text().split()) for text in ax.get_legend().get_texts()]


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
    assert any("Haff's law fitted" in text for text in legend_texts(ax))


def test_no_haff_fit_for_what_is_not_a_cooling_gas():
    """The elastic pi billiard (3 bodies) and an elastic gas get no fit, and the legend says
    why. (Failed before: Haff's law was fitted to the pi billiard.)"""
    pi = cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0])
    texts = legend_texts(plot.temperature(pi))
    assert not any("Haff's law fitted" in t for t in texts)
    assert any('2 bodies are not a gas' in t for t in texts), texts
    rng = np.random.default_rng(3)
    elastic = cl.run(rng.uniform(1, 2, 12), np.arange(12)[::-1] * 1.0, rng.uniform(-1, 1, 12), ring=12.0,
                     max_collisions=300, simulate_to_cap=True)
    texts = legend_texts(plot.temperature(elastic))
    assert any('an elastic gas does not cool' in t for t in texts), texts


def test_plots_need_events():
    run = cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0], events='none')
    with pytest.raises(ValueError, match="events='all'"):
        plot.steps(run)


# --- Plots a class can project (issue 47): readable log ticks, legends off the data, docstrings
# that describe the figure, and the Haff analysis of notebook 5 -------------------------------

# A log tick label as log_ticks writes it: a plain number ('1', '10', '0.01', '2') or 10^n.
READABLE = re.compile(r'^(-?[0-9]+(\.[0-9]+)?|\$10\^\{-?[0-9]+\}\$)$')


def visible_tick_labels(axis):
    """The texts of the tick labels matplotlib draws on `axis` (major and minor, inside the view)."""
    axis.axes.figure.canvas.draw()
    lo, hi = sorted(axis.get_view_interval())
    texts = []
    for ticks in (axis.get_major_ticks(), axis.get_minor_ticks()):
        for tick in ticks:
            if tick.label1.get_visible() and tick.label1.get_text() and lo <= tick.get_loc() <= hi:
                texts.append(tick.label1.get_text())
    return texts


@pytest.mark.parametrize('limits', [(1.0, 500.0), (0.006, 0.5), (2.0, 8.0), (1e-30, 1e3), (0.3, 0.9)])
def test_log_ticks_read_plainly(limits):
    """1, 10, 100 or 10^n, never 2x10^0; an axis narrower than a decade still gets labels."""
    fig, ax = plt.subplots()
    ax.loglog(limits, limits)
    ax.set_xlim(*limits)
    ax.set_ylim(*limits)
    plot.log_ticks(ax)
    for axis in (ax.xaxis, ax.yaxis):
        texts = visible_tick_labels(axis)
        assert len(texts) >= 2, texts
        assert all(READABLE.match(t) for t in texts), texts
        assert not any('times' in t for t in texts)


def test_matplotlib_alone_writes_two_times_ten():
    """The case log_ticks exists for: matplotlib's own labels on a narrow log axis."""
    fig, ax = plt.subplots()
    ax.loglog([2.0, 8.0], [2.0, 8.0])
    assert any('times' in t for t in visible_tick_labels(ax.xaxis))


def test_log_label_by_hand():
    assert [plot.log_label(v) for v in (1.0, 10.0, 100.0, 0.01, 2.0, 0.5, 1e5, 1e-7)] == \
        ['1', '10', '100', '0.01', '2', '0.5', '$10^{5}$', '$10^{-7}$']


def ring_gas(n=12, seed=7, collisions=300):
    rng = np.random.default_rng(seed)
    return cl.run(rng.uniform(1, 2, n), np.arange(n)[::-1] * 1.0, rng.uniform(-1, 1, n), 0.9, ring=float(n),
                  restitution_model='tc', tc=0.001, max_collisions=collisions, simulate_to_cap=True)


def legend_is_outside(ax):
    fig = ax.figure
    fig.canvas.draw()
    legend = ax.get_legend()
    assert legend is not None
    box, area = legend.get_window_extent(), ax.get_window_extent()
    assert not box.overlaps(area), 'the legend covers the data area'
    inside_figure = fig.bbox.x0 - 1 <= box.x0 and box.x1 <= fig.bbox.x1 + 1 and fig.bbox.y0 - 1 <= box.y0 \
        and box.y1 <= fig.bbox.y1 + 1
    assert inside_figure, 'the legend is cut off by the figure'


@pytest.mark.parametrize('view', ['steps', 'xt', 'energy', 'transfer', 'temperature', 'temperature_window'])
def test_legends_sit_outside_the_axes(view):
    pi = cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0])
    if view == 'steps':
        ax = plot.steps(pi)
    elif view == 'xt':
        ax = plot.xt(pi)
    elif view == 'energy':
        ax = plot.energy(cl.run([1, 1, 1], [2, 1, 0], [-1, 0, 0], 0.5))
    elif view == 'transfer':
        ax = plot.energy(pi, transfer=True)
    elif view == 'temperature':
        ax = plot.temperature(ring_gas())
    else:
        run = ring_gas()
        ax = plot.temperature(run, window=(0, 5), free_exponent=True, tau_kinetic=3.0)
    legend_is_outside(ax)


def test_steps_draws_what_its_docstring_says():
    """Simulated velocities as solid steps, the closed form as open circles, the paper's
    eqs. as crosses (the docstring once said dashes and dots)."""
    ax = plot.steps(cl.run([3, 1, 2], [2, 1, 0], [-1, 0, 0]))  # three free bodies: the paper's eqs. apply
    lines = {line.get_label(): line for line in ax.get_lines()}
    simulated = lines['v_A simulated']
    assert simulated.get_linestyle() == '-' and simulated.get_drawstyle() == 'steps-post'
    closed = lines['closed form, after each impact']
    assert closed.get_marker() == 'o' and closed.get_linestyle() == 'None' and closed.get_markerfacecolor() == 'none'
    paper = lines["paper's eqs. (2.15)/(2.16)"]
    assert paper.get_marker() == 'x' and paper.get_linestyle() == 'None'
    doc = ' '.join(plot.steps.__doc__.split())
    assert 'solid steps' in doc and 'open circles' in doc and 'crosses' in doc
    assert '(dashed)' not in doc and '(dotted)' not in doc  # the old words for the circles and crosses
    collapse = cl.run([1, 1, 1], [2, 1, 0], [-1, 0, 0], 0.05)
    marks = [line for line in plot.steps(collapse).get_lines() if line.get_linestyle() == ':']
    assert len(marks) == 1 and 'dotted vertical line' in doc  # a collapse


def test_energy_transfer_draws_what_its_docstring_says():
    ax = plot.energy(cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0]), transfer=True)
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert lines['dE_A simulated'].get_marker() == 'o' and lines['dE_A simulated'].get_markerfacecolor() != 'none'
    assert lines['closed form'].get_marker() == 's' and lines['closed form'].get_markerfacecolor() == 'none'
    assert lines["paper's eqs. (4.4)-(4.7)"].get_marker() == 'x'
    doc = ' '.join(plot.energy.__doc__.split())
    assert 'filled dots' in doc and 'open squares' in doc and 'crosses' in doc


def test_temperature_window_draws_what_its_docstring_says():
    run = ring_gas(collisions=600)
    ax = plot.temperature(run, window=(0, 5), free_exponent=True, tau_kinetic=3.0)
    lines = {line.get_label().split(':')[0].split(' (')[0]: line for line in ax.get_lines()}
    assert lines["Haff's law fitted"].get_linestyle() == '--'
    assert lines['exponent free'].get_linestyle() == ':'
    assert lines["Haff's law, kinetic theory"].get_linestyle() == '-'
    assert lines['T(0) measured'].get_marker() == '<'
    texts = legend_texts(ax)
    assert any(t.startswith('fit window: t = 0 to 5 s') for t in texts), texts
    assert any('tau' in t and t.startswith('the run') for t in texts), texts
    spans = [p for p in ax.patches if p.get_label().startswith('fit window')]
    assert len(spans) == 1  # the window is shaded
    assert all(READABLE.match(t) for t in visible_tick_labels(ax.xaxis) + visible_tick_labels(ax.yaxis))
    doc = ' '.join(plot.temperature.__doc__.split())
    for words in ('red dashed', 'purple dotted', 'green solid', 'shaded grey', 'left-pointing triangle'):
        assert words in doc


def test_free_exponent_fit_recovers_the_exponent():
    t = np.concatenate([[0.0], np.geomspace(0.1, 200, 300)])
    for beta, tau in ((2.0, 5.0), (1.5, 12.0), (1.0, 0.5)):
        fit = plot.fit_haff_exponent(t, 0.7 / (1 + t / tau) ** beta)
        assert fit['beta'] == pytest.approx(beta, rel=1e-6)
        assert fit['tau'] == pytest.approx(tau, rel=1e-6) and fit['t0'] == pytest.approx(0.7, rel=1e-9)
        assert fit['rms_ln_error'] < 1e-8


def test_cooling_exponent_by_hand():
    t = np.geomspace(0.1, 1000, 2000)
    tc, exponent = plot.cooling_exponent(t, 3.0 * t ** -1.3)
    assert exponent == pytest.approx(1.3, rel=1e-9)
    tau = 10.0
    tc, exponent = plot.cooling_exponent(t, 1.0 / (1 + t / tau) ** 2)
    assert exponent == pytest.approx(2 * tc / (tc + tau), abs=0.01)  # Haff: 2 t / (t + tau)


def test_haff_tau_closed_form_for_equal_masses():
    """For equal masses and Gaussian velocities, tau = sqrt(pi m / T0) / ((1 - r^2) n)."""
    rng = np.random.default_rng(1)
    m, n_bodies, length, r = 2.0, 3000, 1500.0, 0.8
    v = rng.normal(0, 0.7, n_bodies)
    T0 = plot.granular_temperature([m] * n_bodies, v)[0]
    expected = math.sqrt(math.pi * m / T0) / ((1 - r ** 2) * n_bodies / length)
    assert plot.haff_tau([m] * n_bodies, v, r, length) == pytest.approx(expected, rel=0.03)


@pytest.mark.parametrize('masses', ['equal', 'unequal'])
def test_haff_tau_is_the_simulated_initial_cooling(masses):
    """4,000 bodies at random places on a ring (molecular chaos holds at the start), r = 0.9:
    over the first 0.2 tau the simulated T(t) gives Haff's tau within 4 % of kinetic theory."""
    rng = np.random.default_rng(3)
    n_bodies, length, r = 4000, 4000.0, 0.9
    x = np.sort(rng.uniform(0, length, n_bodies))[::-1]
    v = rng.normal(0, 1, n_bodies)
    m = np.ones(n_bodies) if masses == 'equal' else rng.uniform(1, 2, n_bodies)
    tau = plot.haff_tau(m, v, r, length)
    run = cl.run(m, x, v, r, ring=length, max_collisions=n_bodies, simulate_to_cap=True, events='none')
    t_end = run.summary['final_time']
    T0 = plot.granular_temperature(m, v)[0]
    T_end = plot.granular_temperature(m, run.summary['final_velocities'])[0]
    assert 0.1 < t_end / tau < 0.4
    simulated_tau = t_end / (math.sqrt(T0 / T_end) - 1)  # T_end = T0 / (1 + t_end / tau)^2
    assert simulated_tau == pytest.approx(tau, rel=0.04)


def test_python_md_haff_example_runs_as_written():
    """docs/python.md's Haff example, run as written: the preset, kinetic theory's tau of about
    17.8 s (the fit over the homogeneous phase gives 17.1 s), the window shaded."""
    docs = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'docs', 'python.md')).read()
    section = docs[docs.index("Haff's law for a cooling gas"):]
    code = re.search(r'```python\n(.*?)```', section, re.S).group(1)
    space = {}
    with pytest.warns(cl.CapWarning):  # the preset stops at its cap of 100,000 impacts
        exec(code, space)
    assert space['tau'] == pytest.approx(17.8, abs=0.05)
    ax = plt.gcf().axes[0]
    assert any(p.get_label().startswith('fit window: t = 0 to 30 s') for p in ax.patches)
