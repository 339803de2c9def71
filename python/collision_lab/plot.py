"""collision_lab.plot: the views of a run that the class page and rviz draw, with matplotlib.

steps(run)        velocities after each impact against the impact number (solid steps),
                  beside the model's predicted values: for three elastic bodies the closed
                  form after every impact (open circles) and the paper's printed eqs.
                  (2.15)/(2.16) (crosses); else the predicted final velocities (a thick
                  dashed stub past the last impact);
xt(run)           worldlines: position x [m] across, time t [s] up (as the page draws them),
                  every line to the run's end; on a ring cut at the seam; a collapse as a star;
energy(run)       per-body kinetic energy (or energy transfer per impact), the total and the
                  heat so far;
temperature(run)  granular temperature T(t) on log-log axes with Haff's law fitted, as the
                  CLI's --temperature-csv computes it (from the run's events, or from that
                  CSV file); or fitted over a window of time only, with the exponent free
                  beside it and the kinetic theory's tau (haff_tau).

Each takes `ax=None` (a new figure) and returns the matplotlib Axes. Made to be projected:
legends sit outside the axes, right of them, so they never cover data (a new figure makes
room for them; with your own `ax`, use a constrained layout or savefig's
bbox_inches='tight'); log axes read 1, 10, 100 or 10^5, never 2x10^0 (log_ticks). Colours are
the views' (docs/web.md, "Bodies: names and colours"): up to 10 bodies the palette by index
(A red, B green, C blue, ...); beyond, the start velocity on the map blue (moving left) ->
purple (at rest) -> red (moving right), scaled by the largest start speed; walls grey. Works
with any backend (Agg included): pyplot is imported only to make a figure when no `ax` is
given.
"""
import math
import textwrap

import numpy as np

# rviz's layout::kParticleRgb, kGrey and the velocity map's ends (include/collision_lab/ros/markers/layout.h).
PALETTE = ((0.95, 0.25, 0.25), (0.25, 0.8, 0.3), (0.3, 0.55, 1.0), (1.0, 0.75, 0.2), (0.75, 0.45, 1.0),
           (0.2, 0.85, 0.85), (1.0, 0.5, 0.75), (0.65, 0.8, 0.25), (1.0, 0.55, 0.3), (0.6, 0.6, 0.95))
WALL_GREY = (0.6, 0.6, 0.6)
MOVING_LEFT_BLUE = (0.2, 0.4, 1.0)
AT_REST_PURPLE = (0.62, 0.42, 0.72)
MOVING_RIGHT_RED = (1.0, 0.2, 0.15)
# Bodies with their own velocity and energy lines (all up to this N), and bodies with a
# worldline (beyond this N, this many evenly spaced, the outermost two included): rviz's.
MAX_PLOTTED_BODIES = 10
MAX_TRACKED_BODIES = 24
# The views' end of a finished run: this times the last event's time (rviz's kEndMargin).
END_MARGIN = 1.25
# A ring's worldline is cut at the seam into at most this many pieces (rviz's bound).
MAX_RING_PIECES = 10000
# The CLI's thinning of T(t) for the fit: the first sample of every 1/50 of a decade of time.
SAMPLES_PER_DECADE = 50


def _new_axes(ax, size=(9.0, 4.2)):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt
    _, ax = plt.subplots(figsize=size, layout='constrained')
    return ax


def _is_wall(run):
    return ~np.isfinite(np.asarray(run.masses, dtype=float))


def velocity_colour(v, v_max):
    """The start-velocity map's colour (r, g, b) of velocity v [m/s] on the scale v_max [m/s]."""
    f = float(np.clip(v / v_max, -1.0, 1.0)) if np.isfinite(v) and v_max > 0 else 0.0
    end = MOVING_LEFT_BLUE if f < 0 else MOVING_RIGHT_RED
    a = abs(f)
    return tuple(r + (e - r) * a for r, e in zip(AT_REST_PURPLE, end))


def velocity_scale(run):
    """The largest start speed of a body that is not a wall [m/s] (1 when all rest)."""
    v = np.abs(np.asarray(run.initial_velocities, dtype=float)[~_is_wall(run)])
    v_max = float(v.max()) if v.size else 0.0
    return v_max if v_max > 0 and math.isfinite(v_max) else 1.0


def body_colours(run):
    """One (r, g, b) per body, as the page and rviz colour them (module docstring)."""
    walls = _is_wall(run)
    n = len(walls)
    by_velocity = n > len(PALETTE)
    v_max = velocity_scale(run) if by_velocity else 1.0
    colours = []
    for i in range(n):
        if walls[i]:
            colours.append(WALL_GREY)
        elif by_velocity:
            colours.append(velocity_colour(run.initial_velocities[i], v_max))
        else:
            colours.append(PALETTE[i])
    return colours


def hex_colour(rgb):
    """'#rrggbb' of (r, g, b) in [0, 1], bytes rounded half away from zero as the page's
    view.body_colours are."""
    return '#' + ''.join('%02x' % int(math.floor(min(max(c, 0.0), 1.0) * 255 + 0.5)) for c in rgb[:3])


def evenly_spaced(count, n):
    """n evenly spaced indices of 0 .. count - 1, the first and last included (all if count <= n)."""
    if count <= n:
        return list(range(count))
    return [j * (count - 1) // (n - 1) for j in range(n)]


def _count_text(n, word='collision'):
    return '{:,} {}{}'.format(int(n), word, '' if n == 1 else 's')


def title_of(run, view):
    """'<view>: <model>, <count> [, truncated][, collapse at t = ...]'."""
    s = run.summary
    parts = [s.get('model', run.model)]
    if s.get('simulated', True):
        parts.append(_count_text(s.get('collision_count', 0)) + (' (truncated)' if s.get('truncated') else ''))
    else:
        predicted = s.get('predicted_collision_count')
        parts.append('not simulated' + ('' if predicted is None else ', predicted ' + _count_text(predicted)))
    if s.get('collapsed'):
        parts.append('collapse at t = %.4g s' % s['collapse_time'])
    if run.scene.get('ring'):
        parts.append('ring of %g m' % run.scene['ring'])
    return '%s\n%s' % (view, ', '.join(parts))


def _require_events(run, view):
    if len(run.events.get('time', ())) == 0 and run.summary.get('collision_count', 0) > 0:
        if not run.summary.get('simulated'):
            raise ValueError('plot.%s needs simulated events: the model answered this run\'s %s without simulating '
                             'them (more than max_collisions, or mode=\'predict\'); raise max_collisions or pass '
                             'simulate_to_cap=True' % (view, _count_text(run.summary['collision_count'])))
        raise ValueError('plot.%s needs the run\'s events: run it with events=\'all\' (this run has %s and none '
                         'recorded)' % (view, _count_text(run.summary['collision_count'])))


def _impacts_and_velocities(run):
    """(impact number [1], velocities [m/s]) at the start (0) and after every event."""
    ev = run.events
    index = np.concatenate([[0], np.asarray(ev.get('index', []), dtype=float)])
    v0 = np.asarray(run.initial_velocities, dtype=float)[None, :]
    after = np.asarray(ev.get('velocities_after', np.empty((0, v0.shape[1]))), dtype=float)
    return index, np.vstack([v0, after])


def _mark_collapses(ax, run):
    ev = run.events
    kinds = np.asarray(ev.get('kind', []))
    for k in np.flatnonzero(kinds == 'collapse'):
        ax.axvline(ev['index'][k], color='0.35', lw=0.8, ls=':')
        ax.annotate('collapse (t = %.4g s)' % ev['time'][k], (ev['index'][k], 1.0), xycoords=('data', 'axes fraction'),
                    xytext=(-4, -4), textcoords='offset points', ha='right', va='top', fontsize=8, color='0.3')


# Legend labels are wrapped at this many characters (the legend sits right of the axes).
LEGEND_WRAP = 36


def legend_outside(ax, ncol=1, **options):
    """The Axes' legend right of it, outside the data area (top-aligned), labels wrapped at
    LEGEND_WRAP characters: a legend that never covers data. Returns the Legend (None when
    nothing is labelled)."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    labels = [textwrap.fill(label, LEGEND_WRAP) for label in labels]
    options.setdefault('fontsize', 8)
    return ax.legend(handles, labels, loc='upper left', bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, ncol=ncol,
                     **options)


def _legend(ax, n_lines):
    if 0 < n_lines <= 14:
        legend_outside(ax, ncol=2 if n_lines > 7 else 1)


def log_label(value, pos=None):
    """A log axis's tick label: a plain number from 1e-4 to 1e4 ('0.01', '1', '10', '2',
    '0.5'), a power of ten beyond as 10^n (mathtext); never 'a x 10^n'."""
    if not (value > 0 and math.isfinite(value)):
        return ''
    exponent = round(math.log10(value))
    if abs(value / 10.0 ** exponent - 1) < 1e-9:  # a power of ten
        return '%g' % 10.0 ** exponent if -4 <= exponent <= 4 else r'$10^{%d}$' % exponent
    return '%g' % value


def log_ticks(ax, axis='both'):
    """Readable log axes (axis 'x', 'y' or 'both'; linear axes are left alone): major ticks at
    the powers of ten, or at 1, 2 and 5 times them where the axis spans less than a decade
    (decided whenever the ticks are drawn, so later limits are followed), labelled by
    log_label; minor ticks unlabelled. Returns the Axes."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    class ReadableLogLocator(LogLocator):
        def tick_values(self, vmin, vmax):
            if vmin > vmax:
                vmin, vmax = vmax, vmin
            narrow = vmin > 0 and math.isfinite(vmax / vmin) and vmax / vmin < 10
            self.set_params(subs=(1.0, 2.0, 5.0) if narrow else (1.0,))
            return super().tick_values(vmin, vmax)

    for name in ('x', 'y') if axis == 'both' else (axis,):
        scaled = getattr(ax, 'get_%sscale' % name)()
        if scaled != 'log':
            continue
        target = ax.xaxis if name == 'x' else ax.yaxis
        target.set_major_locator(ReadableLogLocator(base=10.0, numticks=12))
        target.set_major_formatter(FuncFormatter(log_label))
        target.set_minor_formatter(NullFormatter())
    return ax


def _given(values):
    """values, or None when absent or NaN throughout (the model does not give them)."""
    return None if values is None or np.all(np.isnan(values)) else values


def steps(run, ax=None, bodies=None):
    """Velocities after each impact [m/s] against the impact number: each body's simulated
    velocity as solid steps in its colour, held one impact past the last; where the model
    gives them (three elastic bodies), the closed form after every impact as open circles and
    the paper's printed eqs. (2.15)/(2.16) as crosses, in the body's colour; else the
    predicted final velocities as a thick dashed stub past the last impact. A collapse is a
    dotted vertical line. Up to 10 bodies each has a legend entry (outside the axes, right).
    bodies: indices to draw (default: all up to 10 bodies, else 24 evenly spaced). Returns
    the Axes."""
    _require_events(run, 'steps')
    ax = _new_axes(ax)
    colours = body_colours(run)
    n = len(colours)
    if bodies is None:
        bodies = evenly_spaced(n, MAX_PLOTTED_BODIES if n <= MAX_PLOTTED_BODIES else MAX_TRACKED_BODIES)
    index, v = _impacts_and_velocities(run)
    last = index[-1] if index.size else 0
    # The state after the last impact is held for one more impact's width.
    held = np.append(index, last + 1)
    v = np.vstack([v, v[-1:]])
    ev = run.events
    predicted = _given(ev.get('predicted_velocities_after'))
    paper = _given(ev.get('paper_velocities_after'))
    labelled = n <= MAX_PLOTTED_BODIES
    lines = 0
    for i in bodies:
        name = run.names[i]
        wall = '' if np.isfinite(run.masses[i]) else ' (wall)'
        ax.step(held, v[:, i], where='post', color=colours[i], lw=1.6,
                label=('v_%s simulated%s' % (name, wall)) if labelled else None)
        lines += labelled
        if predicted is not None:
            ax.plot(index[1:], predicted[:, i], ls='none', marker='o', ms=5, mfc='none', mec=colours[i],
                    label='closed form, after each impact' if labelled and i == bodies[0] else None)
        if paper is not None:
            ax.plot(index[1:], paper[:, i], ls='none', marker='x', ms=5, color=colours[i], alpha=0.8,
                    label=("paper's eqs. (2.15)/(2.16)") if labelled and i == bodies[0] else None)
    if predicted is None:
        final = run.summary.get('predicted_final_velocities')
        if final is not None:
            stub = max(1.0, 0.08 * last)
            for j, i in enumerate(bodies):
                if final[i] is not None:
                    ax.plot([last, last + stub], [final[i], final[i]], color=colours[i], lw=3, ls='--',
                            label='predicted final' if labelled and j == 0 else None)
    lines += (predicted is not None) + (paper is not None)
    _mark_collapses(ax, run)
    ax.set_xlabel('impact number (0: the start)')
    ax.set_ylabel('velocity after the impact [m/s]')
    ax.set_title(title_of(run, 'velocities after each impact'), fontsize=10)
    if last <= 40:
        ax.xaxis.get_major_locator().set_params(integer=True)
    ax.grid(alpha=0.3)
    _legend(ax, lines)
    return ax


def end_time(run):
    """The views' end [s]: 1.25 x the last event's time; with no event, the time the widest
    gap takes at the largest speed (rviz's endTime for a finished run)."""
    t = np.asarray(run.events.get('time', []), dtype=float)
    if t.size and t[-1] > 0:
        return END_MARGIN * float(t[-1])
    x = np.asarray(run.initial_positions, dtype=float)
    v = np.asarray(run.initial_velocities, dtype=float)
    gap = float(np.max(x[:-1] - x[1:])) if x.size > 1 else 0.0
    speed = float(np.max(np.abs(v[np.isfinite(v)]))) if v.size else 0.0
    return gap / speed if speed > 0 and gap > 0 else 1.0


def worldline(run, i, t_end=None):
    """(t [s], x [m]) of body i at the start, at every event and at t_end (free flight from
    the last event); on a ring x is unwrapped (continuous, not taken modulo L)."""
    ev = run.events
    t_end = end_time(run) if t_end is None else t_end
    t = np.concatenate([[0.0], np.asarray(ev.get('time', []), dtype=float)])
    x = np.concatenate([[run.initial_positions[i]], np.asarray(ev['positions'])[:, i] if len(t) > 1 else []])
    v = np.concatenate([[run.initial_velocities[i]], np.asarray(ev['velocities_after'])[:, i] if len(t) > 1 else []])
    ring = run.scene.get('ring')
    if ring:
        # Free flight between events: unwrap each event's x to the multiple of L nearest
        # the flown position.
        for k in range(1, len(x)):
            flown = x[k - 1] + v[k - 1] * (t[k] - t[k - 1])
            x[k] += ring * np.round((flown - x[k]) / ring)
    if t_end > t[-1]:
        t = np.append(t, t_end)
        x = np.append(x, x[-1] + v[-1] * (t_end - t[-2]))
    return t, x


def ring_segments(t, x, ring, max_pieces=MAX_RING_PIECES):
    """The unwrapped line (t, x) cut where it crosses the seam: a list of (t, x) pieces with
    x in [0, L], each piece ending and the next starting at the crossing; at most max_pieces
    (rviz's bound on the lines of one body): the line stops at the last crossing kept."""
    pieces, piece_t, piece_x = [], [t[0]], [x[0] % ring]
    turn = math.floor(x[0] / ring)
    for k in range(1, len(t)):
        x0, x1, t0, t1 = x[k - 1], x[k], t[k - 1], t[k]
        target = math.floor(x1 / ring)
        while turn != target:  # every seam crossing on the way, in order
            if len(pieces) + 1 >= max_pieces:
                return pieces
            up = target > turn
            seam = (turn + 1) * ring if up else turn * ring
            at = t0 + (seam - x0) / (x1 - x0) * (t1 - t0)
            piece_t.append(at), piece_x.append(ring if up else 0.0)
            pieces.append((np.array(piece_t), np.array(piece_x)))
            piece_t, piece_x = [at], [0.0 if up else ring]
            turn += 1 if up else -1
        piece_t.append(t1), piece_x.append(x1 - turn * ring)
    pieces.append((np.array(piece_t), np.array(piece_x)))
    return pieces


def xt(run, ax=None, bodies=None):
    """Worldlines: position x [m] across, time t [s] up, one solid line per body in its
    colour, every line (walls and bodies that never collide included) to the run's end
    (1.25 x the last event's time); on a ring x in [0, L) with each line cut at the seam; a
    collapse as a black star. Up to 10 bodies each line has a legend entry (outside the axes,
    right). bodies: indices (default: all up to 24 bodies, else 24 evenly spaced, the
    outermost two included). Returns the Axes."""
    _require_events(run, 'xt')
    ax = _new_axes(ax, size=(7.5, 5.0))
    colours = body_colours(run)
    n = len(colours)
    if bodies is None:
        bodies = evenly_spaced(n, MAX_TRACKED_BODIES)
    t_end = end_time(run)
    ring = run.scene.get('ring')
    labelled = n <= MAX_PLOTTED_BODIES
    for i in bodies:
        t, x = worldline(run, i, t_end)
        pieces = ring_segments(t, x, ring) if ring else [(t, x)]
        for k, (pt, px) in enumerate(pieces):
            ax.plot(px, pt, color=colours[i], lw=1.4 if n <= MAX_PLOTTED_BODIES else 0.9,
                    label=(run.names[i] + (' (wall)' if not np.isfinite(run.masses[i]) else ''))
                    if labelled and k == 0 else None)
    ev = run.events
    kinds = np.asarray(ev.get('kind', []))
    for k in np.flatnonzero(kinds == 'collapse'):
        ax.plot(ev['position'][k], ev['time'][k], marker='*', ms=12, color='k', ls='none',
                label='collapse' if labelled else None)
    ax.set_ylim(0, t_end)
    if ring:
        ax.set_xlim(0, ring)
    ax.set_xlabel('position x [m]' + (' on the ring (0 and L are the seam)' if ring else ''))
    ax.set_ylabel('time t [s]')
    shown = 'all %d bodies' % n if len(bodies) == n else '%d of %s bodies, evenly spaced' % (len(bodies), '{:,}'.format(n))
    ax.set_title(title_of(run, 'worldlines (%s)' % shown), fontsize=10)
    ax.grid(alpha=0.3)
    if labelled:
        legend_outside(ax)
    return ax


def energy(run, ax=None, transfer=False):
    """Energies [J] against the impact number. transfer=False: each body's kinetic energy
    after each impact as steps in its colour (up to 10 bodies), the total kinetic energy
    (thick black steps) and the heat so far (the energy lost by inelastic impacts, summed;
    grey dashed steps). transfer=True: the energy each body gained at each impact (filled
    dots), beside the closed form's (open squares) and the paper's printed eqs. (4.4)-(4.7)
    (crosses) where the model gives them, and a grey line at 0. Legend outside the axes,
    right. Returns the Axes."""
    _require_events(run, 'energy')
    ax = _new_axes(ax)
    colours = body_colours(run)
    n = len(colours)
    ev = run.events
    index = np.concatenate([[0], np.asarray(ev.get('index', []), dtype=float)])
    finite = ~_is_wall(run)
    m = np.asarray(run.masses, dtype=float)
    v0 = np.asarray(run.initial_velocities, dtype=float)
    ke0 = np.where(finite, 0.5 * np.where(finite, m, 0.0) * v0 ** 2, 0.0)
    lines = 0
    if transfer:
        de = np.asarray(ev['energy_transfer'])
        for i in range(min(n, MAX_PLOTTED_BODIES)):
            if not finite[i]:
                continue
            ax.plot(index[1:], de[:, i], ls='none', marker='o', ms=4, color=colours[i],
                    label='dE_%s simulated' % run.names[i])
            lines += 1
        for key, style, label in (('predicted_energy_transfer', dict(marker='s', mfc='none', ms=7), 'closed form'),
                                  ('paper_energy_transfer', dict(marker='x', ms=6), "paper's eqs. (4.4)-(4.7)")):
            if _given(ev.get(key)) is not None:
                for i in range(min(n, MAX_PLOTTED_BODIES)):
                    ax.plot(index[1:], ev[key][:, i], ls='none', color=colours[i], alpha=0.8,
                            label=label if i == 0 else None, **style)
                lines += 1
        ax.axhline(0, color='0.5', lw=0.6)
        ax.set_ylabel('energy gained at the impact [J]')
        view = 'energy transfer per impact'
    else:
        if n <= MAX_PLOTTED_BODIES:
            ke = np.vstack([ke0[None, :], np.asarray(ev['kinetic_energy_after']).reshape(-1, n)])
            for i in range(n):
                if finite[i]:
                    ax.step(index, ke[:, i], where='post', color=colours[i], lw=1.2,
                            label='kinetic energy of %s' % run.names[i])
                    lines += 1
        total = np.concatenate([[ke0.sum()], np.asarray(ev.get('total_energy', []), dtype=float)])
        heat = np.concatenate([[0.0], np.cumsum(np.nan_to_num(np.asarray(ev.get('energy_lost', []), dtype=float)))])
        ax.step(index, total, where='post', color='k', lw=2, label='total kinetic energy')
        ax.step(index, heat, where='post', color='0.45', lw=1.5, ls='--', label='heat so far')
        lines += 2
        ax.set_ylabel('energy [J]')
        view = 'energies after each impact'
    _mark_collapses(ax, run)
    ax.set_xlabel('impact number (0: the start)')
    ax.set_title(title_of(run, view), fontsize=10)
    ax.grid(alpha=0.3)
    _legend(ax, lines)
    return ax


def granular_temperature(masses, velocities):
    """T = (1/N) sum m_i (v_i - V)^2 [J] over the N finite masses, V their centre-of-mass
    velocity (core::granularTemperature): twice the mean kinetic energy of the bodies' motion
    relative to their centre of mass. velocities: one row per state (2-D) or one state."""
    m = np.asarray(masses, dtype=float)
    finite = np.isfinite(m)
    v = np.atleast_2d(np.asarray(velocities, dtype=float))[:, finite]
    m = m[finite]
    if m.size == 0:
        return np.zeros(v.shape[0])
    centre = (v @ m) / m.sum()
    return ((v - centre[:, None]) ** 2 @ m) / m.size


def temperature_samples(run):
    """T(t) as the CLI's --temperature-csv samples it: (impacts [1], t [s], T [J]) at the start,
    after every k-th impact (k = max(1, N/8)), after every collapse and after the last event."""
    _require_events(run, 'temperature')
    ev = run.events
    n = len(run.masses)
    stride = max(1, n // 8)
    index = np.asarray(ev['index'], dtype=np.int64)
    keep = (index % stride == 0) | (np.asarray(ev['kind']) == 'collapse')
    if keep.size:
        keep[-1] = True
    rows = np.flatnonzero(keep)
    T = granular_temperature(run.masses, np.asarray(ev['velocities_after'])[rows])
    T0 = granular_temperature(run.masses, run.initial_velocities)
    return (np.concatenate([[0], index[rows]]), np.concatenate([[0.0], np.asarray(ev['time'])[rows]]),
            np.concatenate([T0, T]))


def thin_log_time(t):
    """Indices of the samples the CLI fits (core::LogTimeSamples): the first of every
    1/50 decade of time (the start's t = 0 kept), and the newest."""
    kept, last_bin, newest = [], -math.inf, None
    for k, tk in enumerate(t):
        b = math.floor(math.log10(tk) * SAMPLES_PER_DECADE) if tk > 0 else -math.inf
        if not kept or b > last_bin:
            kept.append(k)
            last_bin, newest = b, None
        else:
            newest = k
    return kept + ([newest] if newest is not None else [])


def _haff_cost(t, log_T, u):
    r = log_T + 2 * np.log1p(t / math.exp(u))
    log_t0 = r.mean()
    return float(((r - log_t0) ** 2).sum()), log_t0


def _usable_samples(t, T, least):
    """(t [s], ln T) of the samples a fit uses (finite t >= 0, T > 0), or None with fewer than
    `least` of them or none after t = 0."""
    t = np.asarray(t, dtype=float)
    T = np.asarray(T, dtype=float)
    use = np.isfinite(t) & (t >= 0) & np.isfinite(T) & (T > 0)
    t, log_T = t[use], np.log(T[use])
    if t.size < least or not t.max() > 0:
        return None
    return t, log_T


def _golden_min(cost, a, b):
    """The minimum of a unimodal cost(u) on [a, b] by golden sections, to 1e-13 relative."""
    phi = (math.sqrt(5.0) - 1) / 2
    c, d = b - phi * (b - a), a + phi * (b - a)
    fc, fd = cost(c), cost(d)
    while b - a > 1e-13 * max(1.0, abs(a)):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - phi * (b - a)
            fc = cost(c)
        else:
            a, c, fc = c, d, fd
            d = a + phi * (b - a)
            fd = cost(d)
    return (a + b) / 2


_GRID_STEPS = 12 * 20  # fit_haff's grid of ln tau: 0.05 decades over 12


def _best_log_tau(cost, t):
    """(grid index, ln tau) minimising cost(ln tau): the best of a grid of 0.05 decades over
    [1e-6, 1e6] x the last time, refined by golden sections between its neighbours; the index
    is the grid's last (GRID_STEPS) when the cost falls all the way (no cooling seen)."""
    lo = math.log(t.max()) - 6 * math.log(10.0)
    du = 12 * math.log(10.0) / _GRID_STEPS
    best = int(np.argmin([cost(lo + k * du) for k in range(_GRID_STEPS + 1)]))
    return best, _golden_min(cost, lo + max(best - 1, 0) * du, lo + min(best + 1, _GRID_STEPS) * du)


def fit_haff(t, T):
    """Haff's law T(t) = t0 / (1 + t/tau)^2 fitted by least squares on ln T, as core::fitHaff:
    a grid of 0.05 decades in tau over [1e-6, 1e6] x the last time, then golden sections.
    Returns dict(t0 [J], tau [s] (inf: no cooling seen), rms_ln_error [1], samples [1]) or
    None with fewer than two usable samples (finite t >= 0, T > 0) or none after t = 0."""
    samples = _usable_samples(t, T, 2)
    if samples is None:
        return None
    t, log_T = samples
    best, u = _best_log_tau(lambda w: _haff_cost(t, log_T, w)[0], t)
    if best == _GRID_STEPS:
        log_t0 = log_T.mean()
        cost = float(((log_T - log_t0) ** 2).sum())
        tau = math.inf
    else:
        cost, log_t0 = _haff_cost(t, log_T, u)
        tau = math.exp(u)
    return {'t0': math.exp(log_t0), 'tau': tau, 'rms_ln_error': math.sqrt(cost / t.size), 'samples': int(t.size)}


def _free_exponent_fit(t, log_T, u):
    """(cost, ln T0, beta) of ln T = ln T0 - beta ln(1 + t/tau), tau = e^u, by linear least
    squares in (ln T0, beta)."""
    x = np.log1p(t / math.exp(u))
    xc = x - x.mean()
    sxx = float(xc @ xc)
    if not sxx > 0:
        return math.inf, float(log_T.mean()), 0.0
    beta = -float(xc @ (log_T - log_T.mean())) / sxx
    log_t0 = float(log_T.mean() + beta * x.mean())
    r = log_T - (log_t0 - beta * x)
    return float(r @ r), log_t0, beta


def fit_haff_exponent(t, T):
    """T(t) = t0 / (1 + t/tau)^beta with the exponent beta free beside t0 and tau (Haff's law
    has beta = 2), by least squares on ln T: for each tau a linear fit of ln t0 and beta, tau
    on the grid of fit_haff (0.05 decades over [1e-6, 1e6] x the last time), then golden
    sections. Returns dict(t0 [J], tau [s], beta [1], rms_ln_error [1], samples [1]) or None
    with fewer than three usable samples (finite t >= 0, T > 0). Over a window much shorter
    than tau only beta/tau is decided (the law is then exp(-beta t/tau)); the exponent is
    the late-time slope d ln T / d ln t only for t >> tau."""
    samples = _usable_samples(t, T, 3)
    if samples is None:
        return None
    t, log_T = samples
    _, u = _best_log_tau(lambda w: _free_exponent_fit(t, log_T, w)[0], t)
    cost, log_t0, beta = _free_exponent_fit(t, log_T, u)
    return {'t0': math.exp(log_t0), 'tau': math.exp(u), 'beta': beta, 'rms_ln_error': math.sqrt(cost / t.size),
            'samples': int(t.size)}


def cooling_exponent(t, T, decades=0.2):
    """The local cooling exponent -d ln T / d ln t [1] (2 for t^-2): the slope of a straight
    line fitted to (ln t, ln T) over the samples within decades/2 of each of the samples thinned
    as the CLI thins them (t > 0 only). Haff's law T0 / (1 + t/tau)^2 has the exponent
    2 t / (t + tau): 2 only for t >> tau. Returns (t [s], exponent [1]) where at least three
    samples fall in the window."""
    t = np.asarray(t, dtype=float)
    T = np.asarray(T, dtype=float)
    use = np.isfinite(t) & (t > 0) & np.isfinite(T) & (T > 0)
    t, T = t[use], T[use]
    kept = thin_log_time(t)
    log_t, log_T = np.log(t[kept]), np.log(T[kept])
    half = 0.5 * decades * math.log(10.0)
    centres, exponents = [], []
    for c in log_t:
        near = np.abs(log_t - c) <= half
        if near.sum() >= 3:
            centres.append(math.exp(c))
            exponents.append(-np.polyfit(log_t[near], log_T[near], 1)[0])
    return np.array(centres), np.array(exponents)


# Pairs averaged exactly up to this many bodies; beyond, this many random pairs (seeded).
HAFF_TAU_ALL_PAIRS_UP_TO = 3000
HAFF_TAU_SAMPLED_PAIRS = 2_000_000


def haff_tau(masses, velocities, restitution, length):
    """Haff's tau [s] from kinetic theory, for point masses on a line of length L [m] (a ring
    or a box; number density n = N / L) with one restitution r: the initial cooling rate of
    the Boltzmann equation with molecular chaos (colliding pairs uncorrelated), set equal to
    Haff's dT/dt(0) = -2 T0 / tau. A pair meets at the rate n |v_i - v_j| / 2 per body and
    loses (1 - r^2) mu_ij (v_i - v_j)^2 / 2 (mu_ij the reduced mass), and T = (1/N) sum m (v -
    V)^2 is twice the energy per body, so
        tau = 4 T0 / ((1 - r^2) n <mu_ij |v_i - v_j|^3>),
    the average over pairs of bodies (all pairs up to HAFF_TAU_ALL_PAIRS_UP_TO bodies, else
    HAFF_TAU_SAMPLED_PAIRS random pairs, seeded). For equal masses m with Gaussian velocities
    it is tau = sqrt(pi m / T0) / ((1 - r^2) n) = 2 / ((1 - r^2) nu0), nu0 = 2 n sqrt(T0 /
    (pi m)) the collisions per body and second (Haff, J. Fluid Mech. 134, 401 (1983); the
    same Boltzmann estimate as in Brilliantov and Poschel, Kinetic Theory of Granular Gases,
    Oxford 2004, here in one dimension). Walls and infinite masses are left out."""
    m = np.asarray(masses, dtype=float)
    v = np.asarray(velocities, dtype=float)
    finite = np.isfinite(m)
    m, v = m[finite], v[finite]
    n_bodies = m.size
    if n_bodies < 2 or not 0 <= restitution < 1 or not length > 0:
        raise ValueError('haff_tau needs at least two finite bodies, 0 <= restitution < 1 and length > 0')
    T0 = float(granular_temperature(m, v)[0])
    if n_bodies <= HAFF_TAU_ALL_PAIRS_UP_TO:
        i, j = np.triu_indices(n_bodies, 1)
    else:
        rng = np.random.default_rng(0)
        i = rng.integers(0, n_bodies, HAFF_TAU_SAMPLED_PAIRS)
        j = rng.integers(0, n_bodies - 1, HAFF_TAU_SAMPLED_PAIRS)
        j = j + (j >= i)
    mu = m[i] * m[j] / (m[i] + m[j])
    moment = float(np.mean(mu * np.abs(v[i] - v[j]) ** 3))
    return 4 * T0 / ((1 - restitution ** 2) * (n_bodies / length) * moment)


def read_temperature_csv(path):
    """The CLI's --temperature-csv file (run(..., temperature_csv=path) writes it): (a pandas
    DataFrame impacts [1], time_s [s], temperature_J [J], with table.attrs['units'] {'time_s':
    's', 'temperature_J': 'J'}; the fit dict t0_J, tau_s, rms_ln_error, samples, or None
    when the file says there is none)."""
    import pandas as pd
    table = pd.read_csv(path, comment='#')
    table.attrs['units'] = {'time_s': 's', 'temperature_J': 'J'}
    fit = {}
    with open(path) as f:
        for line in f:
            if line.startswith('# haff_fit,'):
                key, _, value = line[len('# haff_fit,'):].strip().partition(',')
                if key in ('t0_J', 'tau_s', 'rms_ln_error', 'samples'):
                    fit[key] = float(value)
    return table, ({'t0': fit['t0_J'], 'tau': fit['tau_s'], 'rms_ln_error': fit['rms_ln_error'],
                    'samples': int(fit['samples'])} if 't0_J' in fit else None)


MIN_GAS_BODIES = 10  # [1] finite bodies for Haff's law of a cooling gas to be fitted


def _is_cooling_gas(run):
    """(True, '') for a gas that cools: at least MIN_GAS_BODIES finite bodies and energy lost;
    else (False, why), in words."""
    bodies = int(np.isfinite(run.masses).sum())
    if bodies < MIN_GAS_BODIES:
        return False, '%d bodies are not a gas (Haff\'s law needs many; at least %d here)' % (bodies, MIN_GAS_BODIES)
    if not (run.summary.get('energy_lost') or 0) > 0:
        return False, 'no energy was lost: an elastic gas does not cool'
    return True, ''


def temperature(run, ax=None, csv=None, window=None, free_exponent=False, tau_kinetic=None):
    """Granular temperature T(t) [J] on log-log axes (solid steps, held between samples) with
    Haff's law T0 / (1 + t/tau)^2. The start (t = 0) cannot sit on a log axis: its measured
    T(0) is a left-pointing triangle at the first sampled time. csv: the path of the CLI's
    --temperature-csv file (from run(..., events='none', temperature_csv=path): no events
    needed); else T is computed from the run's events, sampled as the CLI does.
    window=None: Haff's law fitted to the whole run as the CLI fits it (red dashed).
    window=(t_start, t_end) [s]: fitted to those samples only (thinned as the CLI thins),
    the window shaded grey, the law drawn over the whole run (red dashed); free_exponent=True
    adds T0 / (1 + t/tau)^beta with beta free fitted to the same samples (purple dotted,
    fit_haff_exponent). tau_kinetic [s] (e.g. haff_tau(...)): Haff's law with the measured
    T(0) and this tau, no fitted parameter (green solid), a dotted vertical line at t = tau,
    and the run's length in units of tau. A run that is not a cooling gas (under 10 bodies,
    or no energy lost) gets no law, and the legend says why. Legend outside the axes, right;
    log ticks by log_ticks. Returns the Axes."""
    ax = _new_axes(ax, size=(10.0, 4.6))
    if csv is not None:
        table, fit = read_temperature_csv(csv)
        t, T = table['time_s'].to_numpy(), table['temperature_J'].to_numpy()
    else:
        _, t, T = temperature_samples(run)
        thinned = thin_log_time(t)
        fit = fit_haff(t[thinned], T[thinned])
    gas, why_not = _is_cooling_gas(run)
    after = t > 0
    t_first = t[after].min() if after.any() else 1.0
    tt = np.geomspace(t_first, t.max(), 300) if after.any() else np.array([1.0])
    if not gas:
        fit = None
        ax.plot([], [], ls='none', label="no Haff fit: %s" % why_not)
    if gas and window is not None:
        t_start, t_end = window
        inside = (t >= t_start) & (t <= t_end)
        kept = np.flatnonzero(inside)[thin_log_time(t[inside])]
        fit = fit_haff(t[kept], T[kept])
        ax.axvspan(max(t_start, t_first), t_end, color='0.85', alpha=0.6, lw=0, zorder=0,
                   label='fit window: t = %g to %g s (%d samples)' % (t_start, t_end, len(kept)))
        free = fit_haff_exponent(t[kept], T[kept]) if free_exponent else None
    else:
        free = None
    ax.loglog(t[after], T[after], color='C0', lw=1.6, drawstyle='steps-post',
              label='T(t) simulated (held between samples)')
    ax.plot([t_first], [T[0]], marker='<', color='C0', ms=9, ls='none', label='T(0) measured: %.4g J' % T[0])
    if fit is not None and math.isfinite(fit['tau']):
        where = 'whole run' if window is None else 'window'
        ax.loglog(tt, fit['t0'] / (1 + tt / fit['tau']) ** 2, color='C3', ls='--', lw=1.6,
                  label="Haff's law fitted (%s): T0 = %.3g J, tau = %.3g s, rms in ln T %.2g"
                  % (where, fit['t0'], fit['tau'], fit['rms_ln_error']))
    if free is not None:
        with np.errstate(over='ignore', under='ignore'):
            free_T = free['t0'] / (1 + tt / free['tau']) ** free['beta']
        ax.loglog(tt, free_T, color='C4', ls=':', lw=2.0,
                  label='exponent free (window): beta = %.2f, T0 = %.3g J, tau = %.3g s'
                  % (free['beta'], free['t0'], free['tau']))
    if gas and tau_kinetic is not None:
        ax.loglog(tt, T[0] / (1 + tt / tau_kinetic) ** 2, color='C2', lw=1.4,
                  label="Haff's law, kinetic theory: T(0) measured, tau = %.3g s (no fit)" % tau_kinetic)
        ax.axvline(tau_kinetic, color='C2', ls=':', lw=1)
        ax.annotate('t = tau', (tau_kinetic, 0.02), xycoords=('data', 'axes fraction'), xytext=(3, 0),
                    textcoords='offset points', fontsize=8, color='C2')
        ax.plot([], [], ls='none', label='the run: %.3g s = %.3g tau' % (t.max(), t.max() / tau_kinetic))
    if gas:
        ax.set_ylim(T[T > 0].min() / 2, T.max() * 2)
    ax.set_xlabel('time t [s]')
    ax.set_ylabel('granular temperature T [J]')
    ax.set_title(title_of(run, 'granular temperature T = (1/N) sum m_i (v_i - V)^2'), fontsize=10)
    ax.grid(alpha=0.3, which='both')
    log_ticks(ax)
    legend_outside(ax)
    return ax
