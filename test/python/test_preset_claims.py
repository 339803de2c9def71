"""Every preset's description (config/scenarios.yaml) is true to its run (issue 45).

A description is what a class reads beside a preset, on the class page, in rviz and in
`collision_lab_cli --list`. CLAIMS below holds, by hand and for every preset, what its
description says: counts, which pair collides first, final velocities, times, heat, "no
collision", collapses, the granular temperature T, and the scene's own numbers. The values
come from the physics (docs/physics.md, shared/physics.md), with a one-line derivation
beside each number that is derived; none is copied from the program's output. The tests:
- every preset has a claims entry, and every claims entry a preset;
- each claim's phrase is in the description, each number of a claim is in its phrase, and
  every number of the description belongs to some claim (text and table cannot drift
  apart); a description is one line, in a class's words (an algorithm's name only in its
  closing "How:" note);
- each preset runs as the node and the page serve it (`collision_lab_cli --scenario
  config/scenarios.yaml --name NAME`, which also reads `bodies: FILE` CSVs and the
  restitution model), and every claim is checked against the run;
- the numbers no hand derivation gives (a 1,000-body gas's count, T after 100,000 impacts,
  the collapse times) are derived again by reference loops written here, independent of
  the engine: an exact rational replay for a few bodies and a plain float event loop for
  the gases.
All of it runs in about 3 s: the gases are cheap (the box to its cap of 100,000 impacts
takes 0.3 s), so every preset runs to the end its description speaks of.
"""
import csv
import heapq
import json
import math
import os
import re
import subprocess
from fractions import Fraction

import pytest
import yaml

from conftest import find_program

CONFIG = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'config'))
SCENARIOS = os.path.join(CONFIG, 'scenarios.yaml')
with open(SCENARIOS) as f:
    PRESETS = yaml.safe_load(f)
for _preset in PRESETS.values():  # YAML 1.1 (PyYAML) reads 1.0e4 as a string; the CLI, as 10000
    for _key in ('masses', 'positions', 'velocities'):
        if _key in _preset:
            _preset[_key] = [float(a) for a in _preset[_key]]


# --- Numbers as a description writes them ---------------------------------------------------

class Num:
    """A number of a description: `shown` is how the text writes it ('3,141', '-1/3', '0.67',
    '10^-36'). Exact (N): the text's digits are the whole value. Rounded (R): the text rounds
    `value` to the digits shown, or, with no value, a measured number (checked against the
    run and against a reference loop)."""

    def __init__(self, shown, value=None, exact=True):
        self.shown = shown
        digits = shown.replace(',', '')
        self.digits = Fraction(10) ** int(digits.split('^')[1]) if '^' in digits else Fraction(digits)
        decimals = len(digits.split('.')[1]) if '.' in digits else 0
        self.half_unit = Fraction(1, 2 * 10 ** decimals)
        self.exact = exact
        self.value = self.digits if value is None and exact else value
        if exact:
            assert self.value == self.digits, shown
        elif value is not None:  # the table's value and the text's digits agree
            assert abs(Fraction(value) - self.digits) <= self.half_unit, (shown, float(value))

    def agrees(self, measured):
        if measured is None:
            return False
        if self.value is not None:
            return abs(measured - float(self.value)) <= 1e-9 * max(1.0, abs(float(self.value)))
        return abs(Fraction(measured) - self.digits) <= self.half_unit

    def __int__(self):
        assert self.exact and self.value.denominator == 1, self.shown
        return int(self.value)

    def __repr__(self):
        return self.shown


def N(shown):
    return Num(shown)


def R(shown, value=None):
    return Num(shown, value, exact=False)


# --- Claims ---------------------------------------------------------------------------------

class Claim:
    """A phrase of the description, the numbers it says, and check(ctx) -> None (asserts)."""

    def __init__(self, key, phrase, numbers, check):
        self.key, self.phrase, self.numbers, self.check = key, phrase, list(numbers), check


def body(name):
    """A body's index from its name: A ... Z, then #26, #27, ..."""
    return int(name[1:]) if name.startswith('#') else ord(name) - ord('A')


def impacts(run):
    return [e for e in run['events'] if e['kind'] == 'impact']


def given(phrase, numbers, test):
    """The scene (the preset's own keys) is as the text says."""
    def check(ctx):
        assert test(ctx.preset), 'the scene is not as the text says'
    return Claim('given', phrase, numbers, check)


def count(num, phrase, run='run'):
    """N collisions, then no pair approaches: the run finished, nothing truncated."""
    def check(ctx):
        s = ctx.runs[run]['summary']
        assert s['simulated'] and not s['truncated'], s
        assert s['collision_count'] == int(num), s['collision_count']
    return Claim('count', phrase, [num], check)


def no_collisions(phrase):
    def check(ctx):
        assert ctx.run['summary']['collision_count'] == 0 and ctx.run['events'] == []
    return Claim('count', phrase, [], check)


def capped(num, phrase, run='run'):
    """The run stops at its cap of N impacts, though more would follow."""
    def check(ctx):
        s = ctx.runs[run]['summary']
        assert s['collision_count'] == int(num) and s['truncated'], s
    return Claim('capped', phrase, [num], check)


def forever(phrase):
    """Infinitely many impacts (walls, or a collapse)."""
    def check(ctx):
        assert ctx.run['summary']['predicted_infinite'] is True
    return Claim('forever', phrase, [], check)


def first(pair, phrase):
    def check(ctx):
        assert impacts(ctx.run)[0]['pair'] == pair, impacts(ctx.run)[0]['pair']
    return Claim('first', phrase, [], check)


def order(pairs, phrase):
    """The impacts, pair by pair, in this order."""
    def check(ctx):
        assert [e['pair'] for e in impacts(ctx.run)] == pairs
    return Claim('order', phrase, [], check)


def final(phrase, **velocities):
    """Final velocities [m/s] of the named bodies (the run's summary)."""
    def check(ctx):
        v = ctx.run['summary']['final_velocities']
        for name, num in velocities.items():
            assert num.agrees(v[body(name)]), (name, v[body(name)], num)
    return Claim('final', phrase, velocities.values(), check)


def all_final(num, phrase):
    def check(ctx):
        for v in ctx.run['summary']['final_velocities']:
            assert num.agrees(v), (ctx.run['summary']['final_velocities'], num)
    return Claim('final', phrase, [num], check)


def heat(num, phrase):
    def check(ctx):
        assert num.agrees(ctx.run['summary']['energy_lost']), ctx.run['summary']['energy_lost']
    return Claim('heat', phrase, [num], check)


def impact_at(k, phrase, time=None, position=None):
    """Impact number k (or 'last'): its time [s] and place [m]."""
    def check(ctx):
        event = impacts(ctx.run)[-1 if k == 'last' else k - 1]
        assert k == 'last' or event['index'] == k
        assert time is None or time.agrees(event['time']), event['time']
        assert position is None or position.agrees(event['position']), event['position']
    return Claim('time', phrase, [n for n in (time, position) if n is not None], check)


def ends_at(time, phrase, run='run', key='time'):
    """The run's last impact comes at this time [s] (the summary's final_time)."""
    def check(ctx):
        assert time.agrees(ctx.runs[run]['summary']['final_time']), ctx.runs[run]['summary']['final_time']
    return Claim(key, phrase, [time], check)


def move_apart(phrase):
    """After the run, every neighbour moves away from the next: v_A > v_B > ... strictly."""
    def check(ctx):
        v = ctx.run['summary']['final_velocities']
        assert all(a > b for a, b in zip(v, v[1:])), v
    return Claim('apart', phrase, [], check)


def same_speed_apart(pair, speed, gap, phrase):
    """After the last impact the pair moves at one velocity, `gap` [m] apart, for ever."""
    def check(ctx):
        i, j = body(pair[0]), body(pair[1])
        last = impacts(ctx.run)[-1]
        v = ctx.run['summary']['final_velocities']
        assert v[i] == v[j] and speed.agrees(v[i]), v
        assert gap.agrees(last['positions'][i] - last['positions'][j]), last['positions']
    return Claim('gap', phrase, [speed, gap], check)


def collapses(phrase, *expected):
    """The run's collapses: (time [s], bodies), in order."""
    def check(ctx):
        seen = [e for e in ctx.run['events'] if e['kind'] == 'collapse']
        assert len(seen) == len(expected), seen
        for event, (time, bodies) in zip(seen, expected):
            assert time.agrees(event['time']) and event['bodies'] == list(bodies), (event['time'], event['bodies'])
        assert ctx.run['summary']['collapsed'] is True
    return Claim('collapse', phrase, [time for time, _ in expected], check)


def no_collapse(phrase, run='run'):
    def check(ctx):
        s = ctx.runs[run]['summary']
        assert s['collapsed'] is False and s['cluster_impacts'] == 0, s
    return Claim('no_collapse', phrase, [], check)


def temperature(num, phrase, after=0, run='run', key='T'):
    """The granular temperature T [J] after `after` impacts (0: at the start), from the
    run's T(t) (--temperature-csv)."""
    def check(ctx):
        rows = {impacts: T for impacts, _, T in ctx.runs[run]['temperature']}
        assert num.agrees(rows[after]), rows.get(after)
    return Claim(key, phrase, [num], check)


def critical(num, phrase):
    """The critical restitution r_c of the three bodies (the run's summary)."""
    def check(ctx):
        assert num.agrees(ctx.run['summary']['critical_restitution']), ctx.run['summary']['critical_restitution']
    return Claim('critical', phrase, [num], check)


def angle(degrees, ratio, phrase):
    """The rotation model's angle alpha (degrees) and pi/alpha (the run's summary)."""
    def check(ctx):
        alpha = ctx.run['summary']['alpha']
        assert degrees.agrees(math.degrees(alpha)) and ratio.agrees(math.pi / alpha), alpha
    return Claim('angle', phrase, [degrees, ratio], check)


def pi_digits(num, phrase):
    """The count spells pi's first digits: a text check, and the count claim beside it."""
    def check(ctx):
        assert num.shown == repr(math.pi)[:len(num.shown)]
        assert num.shown.replace('.', '') == str(ctx.run['summary']['collision_count'])
    return Claim('pi', phrase, [num], check)


def claim(key, phrase, numbers, check):
    """A claim of one preset, checked by its own function of ctx."""
    return Claim(key, phrase, numbers, check)


# --- Reference loops, independent of the engine -------------------------------------------

def exact_replay(masses, positions, velocities, e=1, t0=0, cap=10_000):
    """Impacts in exact rational arithmetic (Fraction): bodies right to left, None a wall.
    Returns ([(time, pair index)], velocities) after the last impact, or after `cap`."""
    x = [Fraction(p) for p in positions]
    v = [Fraction(u) for u in velocities]
    e, t, out = Fraction(e), Fraction(t0), []
    while len(out) < cap:
        best = None
        for p in range(len(x) - 1):
            if v[p] < v[p + 1]:
                dt = (x[p] - x[p + 1]) / (v[p + 1] - v[p])
                if best is None or dt < best[0]:
                    best = (dt, p)
        if best is None:
            break
        dt, p = best
        x = [a + b * dt for a, b in zip(x, v)]
        t += dt
        i, j = p, p + 1
        mi, mj = masses[i], masses[j]
        if mi is None:
            v[j] = v[i] - e * (v[j] - v[i])
        elif mj is None:
            v[i] = v[j] - e * (v[i] - v[j])
        else:
            V, rel = (mi * v[i] + mj * v[j]) / (mi + mj), v[i] - v[j]
            v[i], v[j] = V - e * mj * rel / (mi + mj), V + e * mi * rel / (mi + mj)
        out.append((t, p))
    return out, v


def reference_gas(m, x, v, e=1.0, tc=None, ring=None, cap=10 ** 9):
    """A plain float event loop (heap of pair times, lazy positions): bodies right to left,
    inf a wall; the TC rule (elastic when either finite body's last impact is tc or less
    ago); on a ring, pair N-1 joins body N-1 and body 0 seen L to the left.
    Returns (impacts, time of the last, velocities, impacts per pair)."""
    n = len(m)
    x, v, ref, version, last = list(x), list(v), [0.0] * n, [0] * n, [-math.inf] * n
    pairs = n if ring else n - 1
    heap, per_pair, impacts_done, now = [], [0] * pairs, 0, 0.0

    def schedule(p, t):
        i, j = p, (p + 1) % n
        if v[i] < v[j]:
            gap = (x[i] + v[i] * (t - ref[i])) - (x[j] + v[j] * (t - ref[j])) + (ring if p == n - 1 else 0.0)
            heapq.heappush(heap, (t + gap / (v[j] - v[i]), p, version[i], version[j]))
    for p in range(pairs):
        schedule(p, 0.0)
    while heap and impacts_done < cap:
        t, p, vi, vj = heapq.heappop(heap)
        i, j = p, (p + 1) % n
        if version[i] != vi or version[j] != vj:
            continue
        now = t
        for b in (i, j):
            x[b] += v[b] * (t - ref[b])
            ref[b] = t
            version[b] += 1
        ee = 1.0 if tc is not None and any(m[b] < math.inf and t - last[b] <= tc for b in (i, j)) else e
        if m[i] == math.inf:
            v[j] = v[i] - ee * (v[j] - v[i])
        elif m[j] == math.inf:
            v[i] = v[j] - ee * (v[i] - v[j])
        else:
            V, rel = (m[i] * v[i] + m[j] * v[j]) / (m[i] + m[j]), v[i] - v[j]
            v[i], v[j] = V - ee * m[j] * rel / (m[i] + m[j]), V + ee * m[i] * rel / (m[i] + m[j])
        last[i] = last[j] = t
        impacts_done += 1
        per_pair[p] += 1
        for q in {p - 1, p, p + 1}:
            if ring or 0 <= q < pairs:
                schedule(q % pairs, t)
    return impacts_done, now, v, per_pair


def gas_temperature(m, v):
    """T = (1/N) sum m_i (v_i - V)^2 over the finite masses (docs/physics.md)."""
    finite = [(a, b) for a, b in zip(m, v) if a < math.inf]
    V = sum(a * b for a, b in finite) / sum(a for a, _ in finite)
    return sum(a * (b - V) ** 2 for a, b in finite) / len(finite)


def read_bodies(filename):
    with open(os.path.join(CONFIG, filename)) as f:
        rows = list(csv.DictReader(f))
    return ([float(r['mass']) for r in rows], [float(r['position']) for r in rows],
            [float(r['velocity']) for r in rows])


def inversions(velocities):
    """Pairs i < j (i to the right) with v_i < v_j: the equal-mass count (ghosts)."""
    return sum(1 for i in range(len(velocities)) for j in range(i + 1, len(velocities))
               if velocities[i] < velocities[j])


def rotation_alpha(mA, mB, mC):
    """alpha = atan(sqrt(m_B (m_A+m_B+m_C) / (m_A m_C))); a wall C (inf): atan(sqrt(m_B/m_A))."""
    if mC == math.inf:
        return math.atan(math.sqrt(mB / mA))
    return math.atan(math.sqrt(mB * (mA + mB + mC) / (mA * mC)))


# --- The claims table ------------------------------------------------------------------------
# The bodies are listed right to left: A is the rightmost. Times in s, places in m, velocities
# in m/s, energies in J. "t_AB" is the time A and B would meet, gap / closing speed.

def replay_parting(ctx):
    # The doubles of the run show three equal velocities; the exact replay shows the parting.
    hits, v = exact_replay([1, 1, 1], [2, 1, 0], [-1, 0, 0], Fraction(72, 1000))
    assert len(hits) == ctx.run['summary']['collision_count']
    assert all(0 < a - b < Fraction(1, 10 ** 36) for a, b in zip(v, v[1:])), [float(a - b) for a, b in zip(v, v[1:])]


def bounces_spread(ctx):
    times = [e['time'] for e in impacts(ctx.run)]
    gaps = [b - a for a, b in zip(times, times[1:])]
    return len(gaps) > 1 and all(a < b for a, b in zip(gaps, gaps[1:]))


def kinetic_energy(run, masses):
    return sum(0.5 * m * u * u for m, u in zip(masses, run['summary']['final_velocities']) if m != math.inf)


CLAIMS = {
    'equal_masses': [
        given('Three equal masses: A and C move towards B, which is at rest', [],
              lambda p: p['masses'] == [1, 1, 1] and p['velocities'] == [-1, 0, 1]),
        first('AB', 'A hits B first'),  # t_AB = 1 m / 1 m/s = 1 s < t_BC = 2 m / 1 m/s = 2 s
        count(N('3'), 'after 3 collisions'),  # equal masses are ghosts: inversions of (-1, 0, 1) = 3
        final('A, B and C move at 1, 0 and -1 m/s', A=N('1'), B=N('0'), C=N('-1')),  # ghosts: v sorted
    ],
    'general': [
        given('Masses 1, 2 and 3 kg, both pairs moving towards each other', [N('1'), N('2'), N('3')],
              lambda p: p['masses'] == [1, 2, 3] and p['velocities'][0] < p['velocities'][1] < p['velocities'][2]),
        first('AB', 'A hits B first'),  # t_AB = 2 / 1.5 = 1.33 s < t_BC = 2 / 0.5 = 4 s
        count(N('3'), '3 collisions'),  # AB: (1, -0.5, 1); BC: (1, 1.3, -0.2); AB: (1.4, 1.1, -0.2); no pair approaches
    ],
    'bc_first': [
        # t_BC = 1 m / 2 m/s = 1/2 s < t_AB = 2 m / 0.5 m/s = 4 s
        first('BC', 'B and C meet before A reaches B, so the first collision is between B and C'),
        count(N('2'), '2 collisions'),  # BC: (-1/2, 4/3, -2/3); AB: (35/18, 1/9, -2/3); no pair approaches
    ],
    'no_collision': [
        move_apart('All three move apart'),  # v = (1, 0, -1): v_A > v_B > v_C
        no_collisions('no collisions'),  # no pair approaches at the start (v_A >= v_B, v_B >= v_C)
    ],
    'pi_digits_2': [
        given('Block A, 100 times as heavy as block B, pushes B towards a wall (C)', [N('100')],
              lambda p: p['masses'] == [100, 1, math.inf] and p['velocities'] == [-1, 0, 0]),
        count(N('31'), '31 collisions'),  # ceil(pi/alpha) - 1, alpha = atan(1/10): pi/alpha = 31.5
        pi_digits(N('3.1'), 'the first digits of pi (3.1)'),
    ],
    'pi_digits_3': [
        given('A 10,000 times as heavy as B', [N('10,000')], lambda p: p['masses'] == [1e4, 1, math.inf]),
        count(N('314'), '314 collisions'),  # pi / atan(1/100) = 314.2
        pi_digits(N('3.14'), 'pi = 3.14...'),
    ],
    'pi_digits_4': [
        given('A 1,000,000 times as heavy as B', [N('1,000,000')], lambda p: p['masses'] == [1e6, 1, math.inf]),
        count(N('3,141'), '3,141 collisions'),  # pi / atan(1/1000) = 3141.6
        pi_digits(N('3.141'), 'pi = 3.141...'),
    ],
    'pi_digits_5': [
        given('A 100,000,000 times as heavy as B', [N('100,000,000')], lambda p: p['masses'] == [1e8, 1, math.inf]),
        count(N('31,415'), '31,415 collisions'),  # pi / atan(1/10^4) = 31415.9
        pi_digits(N('3.1415'), 'pi = 3.1415...'),
    ],
    'kaleidoscopic': [
        given('Masses 2, 1 and 3 kg', [N('2'), N('1'), N('3')], lambda p: p['masses'] == [2, 1, 3]),
        # AB at t = 1: (-1/3, -4/3, 0); BC at t = 7/4: (-1/3, 2/3, -2/3); AB at t = 5/2 (x = 1/2):
        # (1/3, -2/3, -2/3); C is then at 0 - (2/3)(3/4) = -1/2, 1 m from B
        same_speed_apart('BC', N('-2/3'), N('1'), 'B and C move at the same speed (-2/3 m/s), 1 m apart'),
        count(N('3'), '3 collisions'),
        angle(N('45'), N('4'), 'alpha exactly 45 degrees (pi/alpha = 4)'),  # atan(sqrt(1 * 6 / (2 * 3))) = atan(1)
    ],
    'grazing': [
        given('Masses 3, 1 and 0.5 kg', [N('3'), N('1'), N('0.5')], lambda p: p['masses'] == [3, 1, 0.5]),
        # AB at t = 1: (-1/2, -3/2, 0); BC at t = 1 + 1/1.5 = 5/3: (-1/2, -1/2, -2); A is then at
        # 1 - (1/2)(2/3) = 2/3, B at 0
        same_speed_apart('AB', N('-1/2'), R('0.67', Fraction(2, 3)),
                         'A and B move at the same speed (-1/2 m/s), 0.67 m apart'),
        count(N('2'), '2 collisions'),
        # alpha = atan(sqrt(1 * 4.5 / (3 * 0.5))) = atan(sqrt 3) = 60 degrees
        angle(N('60'), N('3'), 'alpha is exactly 60 degrees here (pi/alpha = 3)'),
    ],
    'heavy_light_heavy': [
        given('A light 1 kg ball between two heavy 1,000,000 kg blocks', [N('1'), N('1,000,000')],
              lambda p: p['masses'] == [1e6, 1, 1e6]),
        # from v = (-1, 0, 0) the state starts on the line n_BC.u = 0 (psi = pi), so the count
        # is ceil(pi/alpha) - 1 = floor(pi/alpha); alpha = atan(sqrt((2e6 + 1) / 1e12)): 2221.44
        count(N('2,221'), 'rattles between them 2,221 times'),
        move_apart('before all three move apart'),
        # alpha = atan(1.41421e-3) = 1.41421e-3 rad = 0.0810 degrees; pi / 1.41421e-3 = 2221.4
        angle(R('0.081'), R('2,221.4'), 'alpha = 0.081 degrees: pi/alpha = 2,221.4'),
    ],
    'moving_wall': [
        given('A is a wall moving left at 0.5 m/s', [N('0.5')],
              lambda p: p['masses'][0] == math.inf and p['velocities'][0] == -0.5),
        # wall hits B at t = 2/0.5 = 4: B -1; BC at 5: (1/3, -2/3); wall-B at 5.6: B -4/3; BC at
        # 6.5: (-4/9, -10/9); wall-B at 20: B -5/9; then -1/2 > -5/9 > -10/9, no pair approaches
        count(N('5'), '5 collisions'),
        claim('work', 'B and C, at rest at first, end with 1.39 J of kinetic energy', [R('1.39', Fraction(25, 18))],
              # 1 (5/9)^2 / 2 + 2 (10/9)^2 / 2 = 25/162 + 200/162 = 25/18 J, from 0 J
              lambda ctx: (ctx.preset['velocities'][1:] == [0, 0]
                           and R('1.39', Fraction(25, 18)).agrees(kinetic_energy(ctx.run, ctx.preset['masses'])))),
    ],
    'two_carts': [
        given('3 kg at -1 m/s meets 1 kg at +1 m/s', [N('3'), N('-1'), N('1')],
              lambda p: p['masses'] == [3, 1] and p['velocities'] == [-1, 1]),
        count(N('1'), '1 collision'),  # two bodies meet at most once
        impact_at(1, 't = 0.5 s, x = 0.5 m', time=N('0.5'), position=N('0.5')),  # gap 1 m, closing 2 m/s; x_A = 1 - 0.5
        final('then they move at 0 and -2 m/s', A=N('0'), B=N('-2')),  # V = -1/2: v' = 2V - v = (0, -2)
    ],
    'two_carts_inelastic': [
        given('Two equal 1 kg carts meet head on at 1 m/s each', [N('1'), N('1')],
              lambda p: p['masses'] == [1, 1] and p['velocities'] == [-1, 1]),
        claim('final', 'bounce back at 0.8 m/s each', [N('0.8')],  # V = 0: v' = -e v
              lambda ctx: ctx.run['summary']['final_velocities'] == [0.8, -0.8]),
        claim('restitution', 'restitution 0.8: 80% of the speed is kept', [N('0.8'), N('80')],
              lambda ctx: ctx.preset['restitution'] == 0.8),
        heat(N('0.36'), '0.36 J turns into heat'),  # (1 - e^2) * 1 J = 0.36 J
    ],
    'cradle_5': [
        given('5 equal masses 1 m apart, the right one at -1 m/s', [N('5'), N('1'), N('-1')],
              lambda p: p['masses'] == [1] * 5 and p['positions'] == [4, 3, 2, 1, 0]
              and p['velocities'] == [-1, 0, 0, 0, 0]),
        count(N('4'), '4 collisions'),  # inversions of (-1, 0, 0, 0, 0): 4
        order(['AB', 'BC', 'CD', 'DE'], 'pass the push along'),  # each impact hands -1 m/s to the next
        final('the left one leaves at -1 m/s', E=N('-1')),  # ghosts: the slowest ends leftmost
    ],
    'ball_between_walls': [
        given('A ball between two walls 1 m apart', [N('1')],
              lambda p: p['masses'] == [math.inf, 1, math.inf] and p['positions'][0] - p['positions'][2] == 1),
        forever('it bounces forever'),
        capped(N('1,000'), 'the run stops after 1,000 bounces'),
        impact_at('last', 't = 999.5 s', time=N('999.5')),  # 0.5 s to the first wall, then 1 s per bounce
    ],
    'bouncing_ball_wall': [
        given('A ball between two walls 1 m apart', [N('1')],
              lambda p: p['masses'] == [math.inf, 1, math.inf] and p['positions'][0] - p['positions'][2] == 1),
        claim('restitution', 'keeps 90% of its speed at each bounce (restitution 0.9)', [N('90'), N('0.9')],
              lambda ctx: ctx.preset['restitution'] == 0.9 and all(
                  abs(abs(e['velocities_after'][1]) - 0.9 ** e['index']) < 1e-12 for e in impacts(ctx.run))),
        claim('slower', 'it gets slower, so the bounces come further and further apart', [],
              bounces_spread),  # bounce k to k+1: 1 m at 0.9^k m/s, so 0.9^-k s
        forever('it never stops bouncing'),
        capped(N('50'), 'the run stops after 50 bounces'),
        # t_50 = 0.5 + sum_{j=1}^{49} 0.9^-j = 0.5 + 10 ((10/9)^49 - 1) = 1736.8 s
        impact_at(50, 'the 50th at t = 1,737 s', time=R('1,737', 0.5 + 10 * ((10 / 9) ** 49 - 1))),
    ],
    'collapse_equal': [
        claim('restitution', 'keep only 5% of their approach speed at each impact (restitution 0.05',
              [N('5'), N('0.05')], lambda ctx: ctx.preset['restitution'] == 0.05 and ctx.preset['masses'] == [1, 1, 1]),
        critical(R('0.0718', 7 - 4 * math.sqrt(3)), 'below the critical 0.0718'),  # r_c = 7 - 4 sqrt 3, equal masses
        forever('infinitely many impacts'),
        collapses('infinitely many impacts before t = 3.5 s', (N('3.5'), 'ABC')),  # the exact replay's times -> 3.5 s
        all_final(N('-1/3'), 'all three move together at -1/3 m/s'),  # momentum -1 kg m/s over 3 kg
        heat(N('1/3'), '1/3 J turns into heat'),  # 1/2 - 3 (1/2)(1/9) = 1/3 J
    ],
    'near_collapse': [
        claim('restitution', 'The same three masses with restitution 0.072', [N('0.072')],
              lambda ctx: ctx.preset['restitution'] == 0.072 and ctx.preset['masses'] == [1, 1, 1]
              and ctx.preset['positions'] == PRESETS['collapse_equal']['positions']
              and ctx.preset['velocities'] == PRESETS['collapse_equal']['velocities']),
        critical(R('0.0718', 7 - 4 * math.sqrt(3)), 'just above the critical 0.0718'),
        no_collapse('no collapse'),
        count(N('63'), 'after 63 impacts'),  # shared/physics.md's reference points: e = 0.072, 63 impacts
        claim('parting', 'the bodies move apart, but at under 10^-36 m/s', [N('10^-36')], replay_parting),
        all_final(N('-1/3'), 'all three seem to move together at -1/3 m/s'),  # -1/3 to within 10^-36
    ],
    'equal_masses_100': [
        given('100 equal masses 1 m apart with random (seeded) velocities', [N('100'), N('1')],
              lambda p: p['masses'] == [1] * 100 and p['positions'] == list(range(99, -1, -1))),
        claim('swap', 'equal masses swap velocities at each impact', [],
              lambda ctx: all(e['pair_velocities_after'] == e['pair_velocities_before'][::-1]
                              for e in impacts(ctx.run))),
        count(N('2,441'), '2,441 collisions'),  # ghosts: the inversions of the listed velocities (recounted below)
        claim('inversions', "one for each pair in which the left body's velocity is greater than the right body's", [],
              lambda ctx: inversions(ctx.preset['velocities']) == ctx.run['summary']['collision_count']),
    ],
    'gas_1000': [
        claim('scene',
              'A gas of 1,000 bodies (random, seeded): masses from 1 to 2 kg, velocities from -1 to 1 m/s, 1 m apart',
              [N('1,000'), N('1'), N('2'), N('-1'), N('1'), N('1')],
              lambda ctx: (len(ctx.run['scene']['masses']) == 1000
                           and all(1 <= m <= 2 for m in ctx.run['scene']['masses'])
                           and all(-1 <= u <= 1 for u in ctx.run['scene']['velocities'])
                           and ctx.run['scene']['positions'] == [float(k) for k in range(999, -1, -1)])),
        count(N('245,308'), '245,308 collisions'),  # no closed form: reference_gas() gives it too (below)
        claim('exact', 'every one computed exactly, until no two neighbours approach', [],
              lambda ctx: (ctx.run['summary']['stop_reason'] == 'FINISHED'
                           and ctx.run['summary']['energy_relative_drift'] <= 1e-15
                           and all(a >= b for a, b in zip(ctx.run['summary']['final_velocities'],
                                                          ctx.run['summary']['final_velocities'][1:])))),
    ],
    # Two runs: 'run' as the CLI and the default lab show it (two walls: the first 1,000
    # impacts), 'to_cap' with --simulate-to-cap (simulate_to_cap:=true), to the cap of 100,000.
    'granular_box_1000': [
        claim('scene', 'the 1,000 bodies of gas_1000 in a box whose walls stand 1 m beyond them', [N('1,000'), N('1')],
              lambda ctx: (ctx.run['scene']['walls'] == ['A', '#1001']
                           and ctx.run['scene']['positions'][:2] == [1000, 999]
                           and ctx.run['scene']['positions'][-2:] == [0, -1]
                           and read_bodies('granular_box_1000.csv')[0][1:-1] == read_bodies('gas_1000.csv')[0])),
        claim('restitution', 'Each impact keeps 90% of the approach speed (restitution 0.9)', [N('90'), N('0.9')],
              lambda ctx: ctx.preset['restitution'] == 0.9),
        claim('tc', "an impact within 1 ms of either body's last one is elastic", [N('1')],
              lambda ctx: (ctx.preset['restitution_model'] == 'tc' and ctx.preset['tc'] == 0.001
                           and ctx.runs['to_cap']['summary']['rule_elastic_impacts'] > 0)),
        no_collapse('so no cluster collapses', run='to_cap'),
        # T0 ~ <m><v^2> = 1.5 kg * (1/3) m^2/s^2 = 0.50 J (masses U[1, 2], velocities U[-1, 1])
        temperature(R('0.50'), 'falls from 0.50 J', key='T0'),
        # measured, no closed form: reference_gas() gives the same (below)
        temperature(R('0.34'), 'to 0.34 J in the first 1,000 impacts', after=1000, key='T_1000'),
        capped(N('1,000'), 'in the first 1,000 impacts'),
        ends_at(R('3.8'), '(t = 3.8 s)', key='t_1000'),
        capped(N('100,000'), 'goes on to 100,000 impacts', run='to_cap'),
        ends_at(R('491'), 't = 491 s', run='to_cap', key='t_cap'),
        temperature(R('0.0065'), 'T = 0.0065 J', after=100000, run='to_cap', key='T_cap'),
    ],
    'granular_ring': [
        claim('ring', 'The same gas on a ring 1,000 m round, with no walls', [N('1,000')],
              lambda ctx: (ctx.preset['ring'] == 1000 and ctx.preset['bodies'] == 'gas_1000.csv'
                           and ctx.run['scene']['walls'] == [])),
        claim('seam', 'the leftmost body (#999) meets the rightmost (A) across the seam', [N('999')],
              lambda ctx: any(e['bodies'] == ['#999', 'A'] for e in ctx.run['events'])),
        claim('restitution', 'Restitution 0.9, elastic within 1 ms as in the box', [N('0.9'), N('1')],
              lambda ctx: (ctx.preset['restitution'] == 0.9 and ctx.preset['restitution_model'] == 'tc'
                           and ctx.preset['tc'] == 0.001)),
        temperature(R('0.50'), 'T falls from 0.50 J', key='T0'),  # as in the box: <m><v^2> = 0.50 J
        temperature(R('0.0061'), 'to 0.0061 J by the cap', after=100000, key='T_cap'),  # measured; reference_gas()
        capped(N('100,000'), 'the cap of 100,000 impacts'),
        ends_at(R('548'), 't = 548 s', key='t_cap'),  # measured; reference_gas() (below)
    ],
    'cluster_collapse_5': [
        given('Five equal masses 1 m apart, the right one at -1 m/s, restitution 0.05', [N('1'), N('-1'), N('0.05')],
              lambda p: (p['masses'] == [1] * 5 and p['positions'] == [4, 3, 2, 1, 0]
                         and p['velocities'] == [-1, 0, 0, 0, 0] and p['restitution'] == 0.05)),
        # A, B, C as collapse_equal (2 m further right): 3.5 s. The cluster (3 kg, -1/3 m/s, at
        # 2 - 1/6 m) reaches D at t = 6 s; then (3, 1, 1) kg at e = 0.05 collapse (exact replay)
        collapses('A, B and C collapse into a cluster at t = 3.5 s, which collapses with D and E at t = 10.43 s',
                  (N('3.5'), 'ABC'), (R('10.43'), 'ABCDE')),
        all_final(N('-0.2'), 'all five move on together at -0.2 m/s'),  # momentum -1 kg m/s over 5 kg
        heat(N('0.4'), '0.4 J turns into heat'),  # 1/2 - 5 (1/2)(0.2^2) = 0.4 J
        claim('cluster', 'A, B and C move as one 3 kg body', [N('3')],
              lambda ctx: all(e['velocities_after'][0] == e['velocities_after'][1] == e['velocities_after'][2]
                              for e in ctx.run['events'] if e['time'] > 3.5)),
    ],
}

# How each preset runs: extra CLI options per run ('T': also write T(t)). Events are kept
# where a claim reads them; the long runs keep none.
RUNS = {
    'pi_digits_4': {'run': ['--events', 'none']},
    'pi_digits_5': {'run': ['--events', 'none']},
    'heavy_light_heavy': {'run': ['--events', 'none']},
    'gas_1000': {'run': ['--events', 'none']},
    'granular_box_1000': {'run': ['--events', 'none', 'T'], 'to_cap': ['--simulate-to-cap', '--events', 'none', 'T']},
    'granular_ring': {'run': ['--full-state-every', '100000', 'T']},  # every impact's pair, for the seam
}

# Words of programs, not of a class: allowed only in a description's closing "How:" note.
PROGRAMMER_WORDS = ('isotonic', 'regression', 'O(', 'event-driven', 'event engine', 'engine', 'model',
                    'alpha', 'closed form', 'algorithm', 'double', 'pi/alpha')

# A number as a description writes it: 10^-36, 3,141 or 2,221.4, -1/3, 0.0065.
NUMBER = re.compile(r"(?<![\w.^/-])(?:\d+\^-?\d+|-?\d{1,3}(?:,\d{3})+(?:\.\d+)?|-?\d+(?:\.\d+)?(?:/\d+)?)")


def claimed(name, key):
    """The value of the claim `key` of a preset (its first number)."""
    found = [c for c in CLAIMS[name] if c.key == key]
    assert found, (name, key)
    return found[0].numbers[0]


# --- Tests ----------------------------------------------------------------------------------

def test_every_preset_has_claims():
    assert set(PRESETS) - set(CLAIMS) == set(), 'presets without a claims entry'
    assert set(CLAIMS) - set(PRESETS) == set(), 'claims of no preset'


@pytest.mark.parametrize('name', sorted(PRESETS))
def test_description_says_its_claims(name):
    text = PRESETS[name]['description']
    assert '\n' not in text.strip(), 'a description is one line'
    claims = CLAIMS.get(name, [])
    assert claims, name + ' has no claims entry'
    said = set()
    for c in claims:
        assert c.phrase in text, 'not in the description: %r' % c.phrase
        tokens = NUMBER.findall(c.phrase)
        for num in c.numbers:
            assert num.shown in tokens, '%s is not a number of the phrase %r' % (num.shown, c.phrase)
            said.add(num.shown)
    unclaimed = [t for t in NUMBER.findall(text) if t not in said]
    assert not unclaimed, 'numbers of the description that no claim checks: %s' % unclaimed
    words = text.split('How:')[0].lower()
    assert not [w for w in PROGRAMMER_WORDS if w.lower() in words], 'programmer words before "How:": ' + words


class Context:
    def __init__(self, name, runs):
        self.name, self.preset, self.runs, self.run = name, PRESETS[name], runs, runs['run']


@pytest.fixture(scope='module')
def run_preset(tmp_path_factory):
    """run_preset(name) -> {run key: the CLI's JSON, plus 'temperature': [(impacts, t, T)]}."""
    cli = find_program('collision_lab_cli')
    folder = tmp_path_factory.mktemp('preset_claims')

    def run(name):
        out = {}
        for key, options in RUNS.get(name, {'run': []}).items():
            args = [cli, '--format', 'json', '--scenario', SCENARIOS, '--name', name]
            csv_path = str(folder / ('%s_%s.csv' % (name, key)))
            args += [a for a in options if a != 'T'] + (['--temperature-csv', csv_path] if 'T' in options else [])
            done = subprocess.run(args, capture_output=True, text=True)
            assert done.returncode == 0, done.stderr
            out[key] = json.loads(done.stdout)
            if 'T' in options:
                with open(csv_path) as f:
                    rows = [line for line in f if line[0].isdigit()]
                out[key]['temperature'] = [(int(a), float(b), float(c)) for a, b, c in csv.reader(rows)]
        return out
    return run


@pytest.mark.parametrize('name', sorted(PRESETS))
def test_run_shows_its_claims(name, run_preset):
    assert name in CLAIMS, name + ' has no claims entry'
    ctx = Context(name, run_preset(name))
    for c in CLAIMS[name]:
        try:
            result = c.check(ctx)
        except AssertionError as error:
            raise AssertionError('%s: %r is not what the run shows: %s' % (name, c.phrase, error)) from None
        assert result is None or result is True, '%s: %r is not what the run shows' % (name, c.phrase)


# The claims table's derived numbers, derived again by code independent of the engine.

def test_counts_from_the_formulas():
    # Galperin: from v = (-1, 0, 0), ceil(pi/alpha) - 1 collisions, alpha = atan(sqrt(m_B/m_A)).
    for name in ('pi_digits_2', 'pi_digits_3', 'pi_digits_4', 'pi_digits_5'):
        mA, mB, mC = PRESETS[name]['masses']
        assert math.ceil(math.pi / rotation_alpha(mA, mB, mC)) - 1 == int(claimed(name, 'count')), name
    alpha = rotation_alpha(*PRESETS['heavy_light_heavy']['masses'])
    assert math.ceil(math.pi / alpha) - 1 == int(claimed('heavy_light_heavy', 'count'))
    assert claimed('heavy_light_heavy', 'angle').agrees(math.degrees(alpha))
    assert abs(math.degrees(rotation_alpha(2, 1, 3)) - float(claimed('kaleidoscopic', 'angle').value)) < 1e-12
    assert abs(math.degrees(rotation_alpha(3, 1, 0.5)) - float(claimed('grazing', 'angle').value)) < 1e-12
    assert inversions(PRESETS['equal_masses_100']['velocities']) == int(claimed('equal_masses_100', 'count'))
    assert inversions(PRESETS['cradle_5']['velocities']) == int(claimed('cradle_5', 'count'))


def test_small_scenes_by_exact_replay():
    # Counts, final velocities and times of the few-body presets, in exact rationals.
    for name in ('equal_masses', 'general', 'bc_first', 'kaleidoscopic', 'grazing', 'moving_wall', 'two_carts',
                 'cradle_5', 'near_collapse'):
        p = PRESETS[name]
        masses = [None if m == math.inf else Fraction(m) for m in p['masses']]
        hits, v = exact_replay(masses, p['positions'], p['velocities'], Fraction(str(p.get('restitution', 1))))
        assert len(hits) == int(claimed(name, 'count')), name
    hits, v = exact_replay([None, 1, 2], [3, 1, 0], [Fraction(-1, 2), 0, 0])
    assert v == [Fraction(-1, 2), Fraction(-5, 9), Fraction(-10, 9)]
    assert claimed('moving_wall', 'work').value == Fraction(1, 2) * v[1] ** 2 + Fraction(2, 2) * v[2] ** 2
    # Collapses: the impact times converge geometrically to the collapse time.
    hits, _ = exact_replay([1, 1, 1], [2, 1, 0], [-1, 0, 0], Fraction(1, 20), cap=40)
    assert abs(hits[-1][0] - claimed('collapse_equal', 'collapse').value) < Fraction(1, 10 ** 18)
    hits, _ = exact_replay([3, 1, 1], [1, 1, 0], [Fraction(-1, 3), 0, 0], Fraction(1, 20), t0=6, cap=40)
    second = [c for c in CLAIMS['cluster_collapse_5'] if c.key == 'collapse'][0].numbers[1]
    assert second.agrees(float(hits[-1][0])) and hits[-1][0] - hits[-2][0] < Fraction(1, 10 ** 20)


def test_gases_by_a_float_event_loop():
    # The measured numbers of the gas texts, from reference_gas(): a program apart from the
    # engine (double arithmetic; the runs it checks are not chaotic enough to part from the
    # exact ones within these digits).
    m, x, v = read_bodies('gas_1000.csv')
    assert reference_gas(m, x, v)[0] == int(claimed('gas_1000', 'count'))
    mb, xb, vb = read_bodies('granular_box_1000.csv')
    assert claimed('granular_box_1000', 'T0').agrees(gas_temperature(mb, vb))
    assert claimed('granular_ring', 'T0').agrees(gas_temperature(m, v))
    done, t, v_end, _ = reference_gas(mb, xb, vb, 0.9, 0.001, cap=1000)
    assert done == 1000 and claimed('granular_box_1000', 't_1000').agrees(t)
    assert claimed('granular_box_1000', 'T_1000').agrees(gas_temperature(mb, v_end))
    done, t, v_end, _ = reference_gas(mb, xb, vb, 0.9, 0.001, cap=100000)
    assert done == 100000 and claimed('granular_box_1000', 't_cap').agrees(t)
    assert claimed('granular_box_1000', 'T_cap').agrees(gas_temperature(mb, v_end))
    done, t, v_end, per_pair = reference_gas(m, x, v, 0.9, 0.001, ring=1000.0, cap=100000)
    assert done == 100000 and claimed('granular_ring', 't_cap').agrees(t)
    assert claimed('granular_ring', 'T_cap').agrees(gas_temperature(m, v_end))
    assert per_pair[-1] > 0  # the seam pair (#999, A) meets
