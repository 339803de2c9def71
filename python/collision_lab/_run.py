"""One scene run in process: collision_lab.run, predict, SceneError and the Run object.

The C++ part (collision_lab._core) takes the scene's numbers straight into the core and runs
it as collision_lab_cli does; it hands back the CLI's JSON report as Python values (no
arguments or JSON text on the way): a Run's report and options are the CLI's JSON, key for
key and value for value, its events numpy columns of the same values; its summary is the
CLI's completed to one set of keys for every model (SUMMARY_KEYS), and its scene is run()'s
keyword arguments (SCENE_KEYS).
"""
import math
import warnings

import numpy as np

from . import _core

# Summary keys that are the model's answer (mode 'predict' gives them without a run).
_PREDICTION_KEYS = ('model', 'model_reason', 'count_formula', 'max_possible_collision_count',
                    'critical_restitution', 'spiral_angle', 'theta', 'alpha', 'omega', 'psi',
                    'paper_phi_bc')
# The keys of every Run's summary, whatever the model (run(), sweep()'s columns; read_bag()
# adds run_id, student and bag_path). The CLI writes two summaries: the three-body report's
# (three elastic bodies: the rotation model's angles, cancelled, truncation_reason) and the
# scene report's (stop_reason, collapses, heat, ...). A key that a run's report lacks is
# filled where the model decides it (below, complete_summary), else None.
SUMMARY_KEYS = ('model', 'model_reason', 'collision_count', 'simulated', 'truncated', 'cancelled',
                'truncation_reason', 'stop_reason', 'stop_message', 'predicted_collision_count',
                'predicted_infinite', 'count_formula', 'matches_prediction', 'max_prediction_error',
                'final_time', 'time_beyond_range', 'energy_lost', 'energy_relative_drift',
                'momentum_relative_drift', 'compute_time_s', 'collapsed', 'collapse_time',
                'collapse_position', 'cluster_impacts', 'rule_elastic_impacts', 'critical_restitution',
                'spiral_angle', 'uncertified_values', 'multiple_collision', 'escalation',
                'final_velocities', 'predicted_final_velocities', 'paper_predicted_collision_count',
                'max_possible_collision_count', 'predicted_first_pair', 'theta', 'alpha', 'omega', 'psi',
                'paper_phi_bc')
# summary['escalation']: the three-body report's keys and the scene report's, None where not given.
ESCALATION_KEYS = ('decisions', 'refinements', 'high_precision', 'exact_rational', 'replayed_impacts')
# The units of the summary's values that have one (sweep() columns: 'multiple_collision.time').
SUMMARY_UNITS = {'final_time': 's', 'energy_lost': 'J', 'compute_time_s': 's', 'collapse_time': 's',
                 'collapse_position': 'm', 'final_velocities': 'm/s', 'predicted_final_velocities': 'm/s',
                 'spiral_angle': 'rad', 'theta': 'rad', 'alpha': 'rad', 'omega': 'rad', 'psi': 'rad',
                 'paper_phi_bc': 'rad', 'multiple_collision.time': 's'}
# The units of Run.to_pandas()'s columns that have one (v_<body> m/s and x_<body> m besides).
EVENT_UNITS = {'time': 's', 'position': 'm', 'energy_lost': 'J', 'total_energy': 'J',
               'total_momentum': 'kg m/s'}
# Run.scene's keys: run()'s keyword arguments but temperature_csv (a file the run writes), so
# that run(**r.scene) runs r's scene again with r's options.
SCENE_KEYS = ('name', 'masses', 'positions', 'velocities', 'restitution', 'ring', 'restitution_model',
              'tc', 'elastic_below', 'viscoelastic_speed', 'max_collisions', 'simulate_to_cap', 'mode',
              'events', 'full_state_every')
# CollisionEvent.FULL_STATE_MAX_BODIES: above this many bodies a record carries the pair's
# fields only (run()'s, as the node's messages): the per-body arrays are a view of one NaN.
FULL_STATE_MAX_BODIES = 64
# Per-event values with one number per body ([m], [m/s], [J]).
_BODY_ARRAYS = ('positions', 'velocities_before', 'velocities_after', 'energy_transfer',
                'kinetic_energy_after')
# Per-body arrays of the three-body model, present where the model gives them.
_MODEL_ARRAYS = ('predicted_velocities_after', 'paper_velocities_after',
                 'predicted_energy_transfer', 'paper_energy_transfer')
# Per-event scalars: name -> numpy dtype (units in docs/python.md).
_SCALARS = (('index', np.int64), ('pair_index', np.int64), ('time', float), ('position', float),
            ('restitution', float), ('energy_lost', float), ('total_energy', float),
            ('total_momentum', float), ('first_moved', np.int64), ('last_moved', np.int64),
            ('cluster_impact', bool))


class SceneError(ValueError):
    """A scene or option the engine rejects: the CLI's JSON error (--format json).

    reason: e.g. 'POSITIONS_COINCIDENT'; code: its number; field: e.g. 'masses[1]';
    message: one sentence saying what is wrong.
    """

    def __init__(self, reason, code, field, message):
        field = field.lstrip('-').replace('-', '_')  # run()'s keyword, not the CLI's option
        super().__init__('invalid %s (%s): %s' % (field, reason, message))
        self.reason = reason
        self.code = code
        self.field = field
        self.message = message


def body_name(index):
    """The core's name of body `index` (0-based): A..Z, then #26, #27, ..."""
    return chr(ord('A') + index) if index < 26 else '#%d' % index


def _body_values(name, values):
    """values as one number per body: a flat list or 1-D array of numbers (not of bools)."""
    array = np.asarray(values)
    if array.ndim == 0:
        array = array.reshape(1)
    if array.ndim != 1:
        raise ValueError('%s must be a list of numbers, one per body, not an array of shape %s'
                         % (name, array.shape))
    # np.asarray([True, 1]) is [1, 1]: a bool among numbers is found in the list itself.
    listed = values if isinstance(values, (list, tuple)) else ()
    if array.dtype == bool or any(isinstance(v, (bool, np.bool_)) for v in listed):
        raise TypeError('%s must be numbers, not True or False' % name)
    if array.size == 0 and name != 'restitution':
        raise ValueError('%s is empty: give one number per body' % name)
    return array


def _plain(value):
    """A number as a Python float, numbers as a list of them (None stays None)."""
    if value is None:
        return None
    if np.ndim(value) == 0:
        return float(value)
    return np.asarray(value, dtype=float).reshape(-1).tolist()


def scene_of(masses, positions, velocities, restitution=1.0, *, ring=None, restitution_model='constant',
             tc=None, elastic_below=None, viscoelastic_speed=None, max_collisions=10_000_000,
             simulate_to_cap=False, events='all', mode='full', name='', full_state_every=1):
    """Run.scene of run()'s (checked) arguments: every key of SCENE_KEYS, numbers as Python
    floats (the doubles the engine was given), so that run(**scene) runs the same scene."""
    return {'name': str(name), 'masses': _plain(masses), 'positions': _plain(positions),
            'velocities': _plain(velocities), 'restitution': _plain(restitution), 'ring': _plain(ring),
            'restitution_model': str(restitution_model), 'tc': _plain(tc), 'elastic_below': _plain(elastic_below),
            'viscoelastic_speed': _plain(viscoelastic_speed), 'max_collisions': int(max_collisions),
            'simulate_to_cap': bool(simulate_to_cap), 'mode': str(mode), 'events': str(events),
            'full_state_every': int(full_state_every)}


def complete_summary(summary):
    """The CLI's summary with every key of SUMMARY_KEYS, in that order (any other key after).

    The three-body report (three elastic bodies, or three that never collide) lacks the
    scene report's keys where the model decides them: elastic impacts neither collapse, stick
    nor lose heat (collapsed False, collapse_time and collapse_position None, cluster_impacts
    and rule_elastic_impacts 0, energy_lost 0.0), and the model counts every impact
    (predicted_infinite False). The scene report lacks cancelled (stop_reason 'CANCELLED') and
    truncation_reason (stop_message when truncated, else ''), as RunSummary has them. Every
    other key a report lacks is None, and escalation has every key of ESCALATION_KEYS.
    """
    if not summary:
        return {}
    given = dict(summary)
    if 'collapsed' not in given:  # the three-body report
        given.update(collapsed=False, collapse_time=None, collapse_position=None, cluster_impacts=0,
                     rule_elastic_impacts=0, energy_lost=0.0)
        given['predicted_infinite'] = False if given.get('predicted_collision_count') is not None else None
    if 'cancelled' not in given:  # the scene report
        given['cancelled'] = given.get('stop_reason') == 'CANCELLED'
        given['truncation_reason'] = (given.get('stop_message') or '') if given.get('truncated') else ''
    escalation = dict(given.get('escalation') or {})
    given['escalation'] = dict({key: escalation.pop(key, None) for key in ESCALATION_KEYS}, **escalation)
    completed = {key: given.pop(key, None) for key in SUMMARY_KEYS}
    completed.update(given)
    return completed


# The CLI's reasons and codes of the option errors that run() words in Python (docs/cli.md).
_USAGE = ('USAGE', 100)
_INVALID_OPTION = ('INVALID_OPTION', 104)


_MODES = ('full', 'predict', 'summary')
_RESTITUTION_MODELS = {'constant': None, 'tc': 'tc', 'threshold': 'elastic_below',
                       'viscoelastic': 'viscoelastic_speed'}


def _whole_number(key, value, least):
    """value as an int from least to 2^64 - 1 (the engine's counts); a bool, a float or a
    string is refused, not rounded."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError('%s must be a whole number, not %r' % (key, value))
    if value < least:
        raise SceneError(*_INVALID_OPTION, key, '%s must be >= %d, not %d' % (key, least, value))
    if value >= 2 ** 64:
        raise SceneError(*_INVALID_OPTION, key, '%s is too large: at most 2^64 - 1, not %d' % (key, value))
    return int(value)


def _check_events(events):
    """events: 'all', 'none' or 'first:N' (N a whole number >= 0)."""
    text = str(events)
    count = text[len('first:'):] if text.startswith('first:') else None
    if text not in ('all', 'none') and not (count and count.isdigit() and count.isascii()):
        raise SceneError(*_INVALID_OPTION, 'events', "events must be 'all', 'none' or 'first:N' with N a whole "
                         "number >= 0, not %r" % (events,))
    return text


def _check_options(restitution, restitution_model, tc, elastic_below, viscoelastic_speed,
                   max_collisions, mode='full', events='all', full_state_every=1, temperature_csv=None):
    """The options' mistakes in run()'s words (its keywords, not the command line's options)."""
    _whole_number('max_collisions', max_collisions, 0)
    _whole_number('full_state_every', full_state_every, 1)
    if np.ndim(restitution) != 0 and np.size(restitution) == 0:
        raise SceneError(*_USAGE, 'restitution', 'restitution is empty: give one e for every pair, '
                         'one per pair, or leave it out (elastic)')
    if restitution_model not in _RESTITUTION_MODELS:
        raise SceneError(*_INVALID_OPTION, 'restitution_model', "restitution_model must be 'constant', 'tc', "
                         "'threshold' or 'viscoelastic', not %r" % (restitution_model,))
    for key, value, model in (('tc', tc, 'tc'), ('elastic_below', elastic_below, 'threshold'),
                              ('viscoelastic_speed', viscoelastic_speed, 'viscoelastic')):
        if value is not None and restitution_model != model:
            raise SceneError(*_USAGE, key, "%s= belongs to restitution_model='%s' (it is %r)"
                             % (key, model, restitution_model))
    if mode not in _MODES:
        raise SceneError(*_INVALID_OPTION, 'mode', "mode must be 'full', 'predict' or 'summary', not %r" % (mode,))
    _check_events(events)
    if temperature_csv is not None and mode != 'full':
        raise SceneError(*_INVALID_OPTION, 'temperature_csv',
                         "T(t) needs the simulation's impacts: mode='full' (the default), not %r" % (mode,))


def _one_number(key, value):
    """A scalar option (ring, tc, ...) as a float; None stays None."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)) or np.ndim(value) != 0:
        raise TypeError('%s must be one number, not %r' % (key, value))
    return float(value)


def core_job(masses, positions, velocities, restitution=1.0, *, ring=None,
             restitution_model='constant', tc=None, elastic_below=None,
             viscoelastic_speed=None, max_collisions=10_000_000, simulate_to_cap=False,
             events='all', mode='full', temperature_csv=None, full_state_every=1, name=''):
    """The checked keyword arguments of run() as the dict that collision_lab._core runs."""
    masses, positions, velocities = (np.asarray(_body_values(key, values), dtype=float) for key, values in
                                     (('masses', masses), ('positions', positions),
                                      ('velocities', velocities)))
    _check_options(restitution, restitution_model, tc, elastic_below, viscoelastic_speed,
                   max_collisions, mode, events, full_state_every, temperature_csv)
    if np.ndim(restitution) != 0:
        restitution = np.asarray(_body_values('restitution', restitution), dtype=float)
    else:
        e = _one_number('restitution', restitution)
        # The default, elastic, as the CLI without --restitution: its report shows no list.
        restitution = np.empty(0) if e == 1.0 else np.asarray([e])
    parameter_key = _RESTITUTION_MODELS[restitution_model]
    parameters = {'tc': tc, 'elastic_below': elastic_below, 'viscoelastic_speed': viscoelastic_speed}
    return {'masses': masses, 'positions': positions, 'velocities': velocities, 'restitution': restitution,
            'ring': _one_number('ring', ring), 'restitution_model': str(restitution_model),
            'model_parameter': _one_number(parameter_key, parameters[parameter_key]) if parameter_key else None,
            'max_collisions': int(max_collisions), 'simulate_to_cap': bool(simulate_to_cap),
            'events': str(events), 'mode': str(mode), 'full_state_every': int(full_state_every),
            'name': str(name), 'temperature_csv': None if temperature_csv is None else str(temperature_csv)}


def result_of(result):
    """(report, events) of collision_lab._core.run's result; raises SceneError for its error
    and MemoryError when the events would not fit in memory."""
    if 'memory' in result:
        raise MemoryError(result['memory'])
    if 'error' in result:
        error = result['error']
        raise SceneError(error['reason'], error['code'], error['field'], error['message'])
    return result['report'], result['events']


def _float_rows(rows, bodies):
    """events x bodies floats; NaN where the JSON has null (a whole null row: all NaN). When
    every row is null (more than 64 bodies: the record has no per-body arrays), a read-only
    view of one NaN, which holds no events x bodies memory: Run.state_at rebuilds states."""
    if all(row is None for row in rows):
        return np.broadcast_to(np.float64(np.nan), (len(rows), bodies))
    out = np.full((len(rows), bodies), np.nan)
    for i, row in enumerate(rows):
        if row is not None:
            out[i, :len(row)] = [np.nan if v is None else v for v in row]
    return out


def _uncertified_column(names):
    """Per event, the names of its values not certified correctly rounded (a tuple each)."""
    column = np.empty(len(names), dtype=object)
    for i, value in enumerate(names):
        column[i] = tuple(value)
    return column


def events_from_records(events, bodies):
    """The event columns of a list of event dicts (the CLI's JSON events, a bag's messages):
    NaN where a record has null, or leaves a key out (the full state of a lean event, or of
    a scene of more than 64 bodies)."""
    arrays = {'kind': np.array([e['kind'] for e in events], dtype=str),
              'pair': np.array([e['pair'] for e in events], dtype=str)}
    for key, dtype in _SCALARS:
        values = [e.get(key) for e in events]
        arrays[key] = (np.array(values, dtype=dtype) if dtype is not float
                       else np.array([np.nan if v is None else v for v in values], dtype=float))
    for key in _BODY_ARRAYS:
        arrays[key] = _float_rows([e.get(key) for e in events], bodies)
    # What every event carries, whatever its record: the colliding pair's velocities [m/s]
    # and energy transfers [J].
    for key in ('pair_velocities_before', 'pair_velocities_after', 'pair_energy_transfer'):
        arrays[key] = _float_rows([e.get(key) for e in events], 2)
    for key in _MODEL_ARRAYS:
        rows = [e.get(key) for e in events]
        if any(row is not None for row in rows):
            arrays[key] = _float_rows(rows, bodies)
    arrays['uncertified'] = _uncertified_column([e.get('uncertified', ()) for e in events])
    return arrays


def _events_from_core(columns, bodies):
    """The event columns that collision_lab._core filled, in events_from_records' layout.
    The per-body arrays that the records do not carry (more than 64 bodies) are a read-only
    view of one NaN, which holds no events x bodies memory: Run.state_at rebuilds states."""
    columns = dict(columns)
    count = len(columns['time'])
    arrays = {'kind': np.where(columns.pop('collapse'), 'collapse', 'impact').astype(str),
              'pair': np.array(columns.pop('pair'), dtype=str)}
    arrays.update((key, columns.pop(key)) for key, _ in _SCALARS)
    for key in _BODY_ARRAYS:
        given = columns.pop(key)
        arrays[key] = given if given is not None else np.broadcast_to(np.float64(np.nan), (count, bodies))
    arrays['uncertified'] = _uncertified_column(columns.pop('uncertified'))
    arrays.update(columns)
    return arrays


class Run:
    """One scene's run: the CLI's JSON report as Python values, its events as numpy arrays.

    scene: run()'s keyword arguments for this run (SCENE_KEYS): run(**r.scene) runs it again
    (the same count and final velocities, bit for bit). summary: the CLI's summary under
    every key of SUMMARY_KEYS, for every model (complete_summary). options, units: the
    report's objects as dicts (null -> None); report: the JSON document but its events (its
    'scene' has the CLI's description, bodies and walls). model, model_reason: the model that
    answered, and why. prediction: the model's answer (the summary's predicted_* and model
    fields; equal to predict()). events: dict of numpy arrays, one entry per event in order
    (see docs/python.md for the keys and units). names: the bodies' names; walls: the names
    of the walls; masses [kg] (inf: a wall), initial_positions [m], initial_velocities
    [m/s]: numpy arrays.
    """

    def __init__(self, report, scene, summary=None, events=None):
        self.report = report
        self.scene = scene
        self.summary = complete_summary(report.get('summary', {})) if summary is None else summary
        self.options = report['options']
        self.units = report['units']
        self.model = self.summary.get('model') or ''
        self.model_reason = self.summary.get('model_reason') or ''
        self.prediction = prediction_of(self.summary)
        self.masses = np.asarray(scene['masses'], dtype=float)
        self.initial_positions = np.asarray(scene['positions'], dtype=float)
        self.initial_velocities = np.asarray(scene['velocities'], dtype=float)
        self.names = [body_name(i) for i in range(len(self.masses))]
        self.walls = [name for name, mass in zip(self.names, self.masses) if math.isinf(mass)]
        self.events = events if events is not None else events_from_records([], len(self.masses))

    def state_at(self, k=None, *, t=None):
        """The bodies' state (positions [m], velocities [m/s]), each an array of one value per
        body: after event k (1-based; 0: the start) of the recorded events, or at time t [s]
        (a float, or an array like solve_ivp's t_eval: then arrays of shape (len(t), bodies)).
        Rebuilt from the events' pair fields, which every record carries, so it needs no
        dense events x bodies array; between events each body flies freely (on a ring,
        wrapped into [0, L)). After the last recorded event the bodies fly on only when the
        record is the whole run (every impact recorded, the run finished); otherwise a time
        past it is refused (ValueError): events='first:N' or 'none', a cap, a stop."""
        if (k is None) == (t is None):
            raise TypeError('give either k (an event number) or t (a time in seconds)')
        e = self.events
        count = len(e['time'])
        if k is not None:
            if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k <= count:
                raise ValueError('k must be a whole number from 0 to %d (the recorded events), not %r' % (count, k))
            x, v, since = self._replay_to(int(k))
            at = e['time'][k - 1] if k > 0 else 0.0
            return self._flown(x, v, since, at), v
        times = np.atleast_1d(np.asarray(t, dtype=float))
        if np.any(~np.isfinite(times)) or np.any(times < 0):
            raise ValueError('t must be finite times >= 0 [s]')
        last = e['time'][-1] if count else 0.0
        if not self._whole_run() and np.any(times > last):
            raise ValueError('the record ends at t = %r s (%d events of a run of %s impacts, %s): no state after it'
                             % (float(last), count, self.summary.get('collision_count'),
                                self.summary.get('truncation_reason') or self.summary.get('stop_reason')
                                or 'events not all recorded'))
        positions = np.empty((len(times), len(self.masses)))
        velocities = np.empty_like(positions)
        # One replay, forward through the times in order.
        order = np.argsort(times, kind='stable')
        replay = self._replay()
        x, v, since = next(replay)
        done = 0
        for row in order:
            wanted = int(np.searchsorted(e['time'], times[row], side='right'))
            while done < wanted:
                x, v, since = next(replay)
                done += 1
            positions[row], velocities[row] = self._flown(x, v, since, times[row]), v
        return (positions[0], velocities[0]) if np.ndim(t) == 0 else (positions, velocities)

    def _whole_run(self):
        """Is every impact of the run recorded, and the run over (no cap, stop or model)?"""
        s = self.summary
        impacts = int(np.sum(self.events['kind'] == 'impact'))
        return (bool(s.get('simulated')) and not s.get('truncated') and not s.get('cancelled')
                and impacts == s.get('collision_count'))

    def _replay_to(self, k):
        """Each body's last point [m], its time [s] and its velocity [m/s] after event k."""
        replay = self._replay()
        state = next(replay)
        for _ in range(k):
            state = next(replay)
        return state

    def _replay(self):
        """Yields (last point [m], its time [s], velocity [m/s]) of every body at the start,
        then after each event in turn (the arrays are updated in place)."""
        e = self.events
        x = self.initial_positions.copy()
        v = self.initial_velocities.copy()
        since = np.zeros(len(x))
        n = len(x)
        yield x, v, since
        for j in range(len(e['time'])):
            first, pair, last = int(e['first_moved'][j]), int(e['pair_index'][j]), int(e['last_moved'][j])
            after = e['pair_velocities_after'][j]
            collapse = e['kind'][j] == 'collapse'
            span = (last - first) % n + 1  # a ring's seam wraps
            for step in range(span):
                body = (first + step) % n
                right_side = collapse or (step <= (pair - first) % n)
                x[body], since[body] = e['position'][j], e['time'][j]
                v[body] = after[0] if right_side else after[1]
            yield x, v, since

    def _flown(self, x, v, since, time):
        flown = x + v * (time - since)
        ring = self.scene.get('ring')
        return np.mod(flown, ring) if ring else flown

    def to_pandas(self, bodies=None):
        """One row per event: kind, pair and the scalar fields, then v_A, v_B, ... (velocities
        after the event [m/s]) and x_A, x_B, ... (positions at the event [m]).
        table.attrs['units']: column -> unit of every column that has one.

        bodies: whose v_/x_ columns. None (the default): every body's, from the per-body
        arrays, for a scene of at most 64 bodies (FULL_STATE_MAX_BODIES; NaN in an event
        that carries no full state, full_state_every); above 64 bodies none, since the
        record has no per-body arrays and the table would take events x bodies x 16 bytes
        (1.6 GB for 100,000 events of 1,000 bodies): use state_at(k) / state_at(t=...) for
        every body's state, or ask for the bodies you want here. A list of bodies (names
        'A', '#70', or 0-based indices) or 'all': those bodies' columns rebuilt from the
        pair fields in one pass over the events, as state_at gives them (velocities exact,
        positions flown from each body's last contact), for any number of bodies and for
        every event of a lean record too; they take events x len(bodies) x 16 bytes. The
        same for run()'s and read_bag()'s runs."""
        import pandas as pd
        columns = {key: self.events[key] for key in ('kind', 'pair') + tuple(k for k, _ in _SCALARS)}
        if bodies is None:
            shown = list(range(len(self.names))) if len(self.names) <= FULL_STATE_MAX_BODIES else []
            velocities = {i: self.events['velocities_after'][:, i] for i in shown}
            positions = {i: self.events['positions'][:, i] for i in shown}
        else:
            shown = self._body_indices(bodies)
            rebuilt_x, rebuilt_v = self._states_at_events(shown)
            velocities = {i: rebuilt_v[:, c] for c, i in enumerate(shown)}
            positions = {i: rebuilt_x[:, c] for c, i in enumerate(shown)}
        for i in shown:
            columns['v_' + self.names[i]] = velocities[i]
        for i in shown:
            columns['x_' + self.names[i]] = positions[i]
        table = pd.DataFrame(columns)
        units = dict(EVENT_UNITS)
        units.update(('v_' + self.names[i], 'm/s') for i in shown)
        units.update(('x_' + self.names[i], 'm') for i in shown)
        table.attrs['units'] = units
        return table

    def _body_indices(self, bodies):
        """to_pandas' bodies (names, 0-based indices or 'all') as indices, in the order given."""
        if isinstance(bodies, str) and bodies == 'all':
            return list(range(len(self.names)))
        if isinstance(bodies, (str, int, np.integer)):
            bodies = [bodies]
        indices = []
        for body in bodies:
            if isinstance(body, str) and body in self.names:
                indices.append(self.names.index(body))
            elif (isinstance(body, (int, np.integer)) and not isinstance(body, bool)
                  and 0 <= body < len(self.names)):
                indices.append(int(body))
            else:
                raise ValueError("bodies: %r is not a body of this run (names %s .. %s, or indices 0 .. %d, or 'all')"
                                 % (body, self.names[0], self.names[-1], len(self.names) - 1))
        return indices

    def _states_at_events(self, indices):
        """(positions [m], velocities [m/s]) of the bodies `indices` after each event, arrays
        of shape (events, len(indices)): state_at(k) for k = 1 .. events in one replay."""
        e = self.events
        count = len(e['time'])
        indices = np.asarray(indices, dtype=np.intp)
        positions = np.empty((count, len(indices)))
        velocities = np.empty_like(positions)
        replay = self._replay()
        next(replay)  # the start
        for j, (x, v, since) in enumerate(replay):
            positions[j] = self._flown(x[indices], v[indices], since[indices], e['time'][j])
            velocities[j] = v[indices]
        return positions, velocities

    def __repr__(self):
        return '<collision_lab.Run %d bodies, model %s, %s collisions>' % (
            len(self.masses), self.model, self.summary.get('collision_count'))

    def _repr_html_(self):
        """A notebook's view: the bodies (up to 12), the model and why, and the summary's
        counts and checks, with units."""
        from html import escape
        s = self.summary

        def value(x):
            if x is None:
                return '&ndash;'
            if isinstance(x, bool):
                return 'yes' if x else 'no'
            if isinstance(x, int):
                return format(x, ',')
            if isinstance(x, float):
                return '%.10g' % x
            return escape(str(x))

        shown = min(len(self.masses), 12)
        bodies = ''.join('<tr><td>%s</td><td>%s</td><td>%s</td><td>%s</td></tr>' % (
            escape(self.names[i]), 'wall' if math.isinf(self.masses[i]) else value(float(self.masses[i])),
            value(float(self.initial_positions[i])), value(float(self.initial_velocities[i]))) for i in range(shown))
        more = '' if shown == len(self.masses) else '<tr><td colspan="4">... %s bodies in all</td></tr>' % format(
            len(self.masses), ',')
        rows = [('collisions', s.get('collision_count'), ''),
                ('simulated', s.get('simulated'), ''),
                ('predicted collisions', s.get('predicted_collision_count'), ''),
                ("the paper's formula", s.get('paper_predicted_collision_count'), ''),
                ('truncated', s.get('truncated'), escape(s.get('truncation_reason') or '')),
                ('max prediction error', s.get('max_prediction_error'), 'ratio'),
                ('energy drift', s.get('energy_relative_drift'), 'ratio'),
                ('momentum drift', s.get('momentum_relative_drift'), 'ratio'),
                ('compute time', s.get('compute_time_s'), 's')]
        summary = ''.join('<tr><th style="text-align:left">%s</th><td>%s</td><td>%s</td></tr>' % (name, value(x), unit)
                          for name, x, unit in rows if x is not None)
        return ('<div><b>collision_lab run</b>: %d bodies, model <code>%s</code> (%s)'
                '<table><tr><th>body</th><th>mass [kg]</th><th>x [m]</th><th>v [m/s]</th></tr>%s%s</table>'
                '<table>%s</table></div>' % (len(self.masses), escape(self.model), escape(self.model_reason),
                                             bodies, more, summary))


class CapWarning(UserWarning):
    """The cap (max_collisions) left a run unsimulated or cut it short."""


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped run(): `run` is the Run as far as it was simulated (its summary says
    cancelled, its events are the impacts before the stop). A KeyboardInterrupt, so that
    code that stops on Ctrl-C still does."""

    def __init__(self, run):
        super().__init__('the run was stopped (Ctrl-C) after %d impacts; .run holds what it simulated'
                         % run.summary.get('collision_count', 0))
        self.run = run

    def __reduce__(self):  # across processes (a pool's workers stopped by Ctrl-C too)
        return RunInterrupted, (self.run,)


def _warn_about_cap(result, max_collisions, simulate_to_cap, mode):
    """Says, as a CapWarning, when the cap decided what was simulated."""
    s = result.summary
    predicted = s.get('predicted_collision_count')
    if mode != 'predict' and not s.get('simulated') and predicted is not None and predicted > max_collisions:
        warnings.warn('the model predicts %s collisions, more than max_collisions=%s: nothing was simulated, the '
                      'model answered (no events). Raise max_collisions, or pass simulate_to_cap=True to simulate '
                      'the first %s.' % (format(predicted, ','), format(max_collisions, ','),
                                         format(max_collisions, ',')), CapWarning, stacklevel=3)
    elif s.get('truncated') and s.get('collision_count') == max_collisions:
        warnings.warn('the run stopped at max_collisions=%s (truncated)%s; raise max_collisions to simulate more.'
                      % (format(max_collisions, ','),
                         '' if predicted is None else ' of the %s the model predicts' % format(predicted, ',')),
                      CapWarning, stacklevel=3)


def prediction_of(summary):
    """The summary's fields that are the model's answer (predicted_*, model, ...)."""
    return {key: value for key, value in summary.items()
            if key in _PREDICTION_KEYS or 'predicted' in key}


def run(masses, positions, velocities, restitution=1.0, *, ring=None, restitution_model='constant',
        tc=None, elastic_below=None, viscoelastic_speed=None, max_collisions=10_000_000,
        simulate_to_cap=False, events='all', mode='full', name='', temperature_csv=None,
        full_state_every=1):
    """Runs one scene in process (as collision_lab_cli --format json) and returns a Run.

    masses [kg] (inf: a wall, first or last), positions [m] strictly decreasing, velocities
    [m/s], one per body, right to left. restitution [1]: one e, or one per pair.
    ring: circumference L [m] (no walls). restitution_model: 'constant', 'tc' (tc [s]),
    'threshold' (elastic_below [m/s]) or 'viscoelastic' (viscoelastic_speed [m/s]).
    max_collisions: the cap; simulate_to_cap: simulate up to it even when the model
    answers. events: 'all', 'none' or 'first:N'. mode: 'full', 'predict' or 'summary'.
    name: the scene's name. temperature_csv: a path to write T(t) [J] to, as the CLI's.
    full_state_every: K > 1 gives the lean record of long runs: every body's state (the
    per-body event arrays) at impact 1 and every K-th impact only, NaN in the others.
    The GIL is released while it runs; Ctrl-C stops it and raises RunInterrupted (a
    KeyboardInterrupt) whose .run is the run as far as it went (a run the plan knows to be
    short, at most 16,384 impacts, ends first: then a plain KeyboardInterrupt). Raises
    MemoryError when the events outgrow the memory that can hold them.
    Raises SceneError for a scene or option the CLI rejects. Warns (CapWarning) when the
    cap left the run unsimulated (the model answered) or cut it short.
    The Run's scene holds these arguments (but temperature_csv): run(**r.scene) runs r again.
    """
    job = core_job(masses, positions, velocities, restitution, ring=ring,
                   restitution_model=restitution_model, tc=tc, elastic_below=elastic_below,
                   viscoelastic_speed=viscoelastic_speed, max_collisions=max_collisions,
                   simulate_to_cap=simulate_to_cap, events=events, mode=mode,
                   temperature_csv=temperature_csv, full_state_every=full_state_every, name=name)
    scene = scene_of(job['masses'], job['positions'], job['velocities'], restitution, ring=ring,
                     restitution_model=restitution_model,
                     tc=tc, elastic_below=elastic_below, viscoelastic_speed=viscoelastic_speed,
                     max_collisions=max_collisions, simulate_to_cap=simulate_to_cap, events=events, mode=mode,
                     name=name, full_state_every=full_state_every)
    outcome, interrupted = _core.run(job)
    report, columns = result_of(outcome)
    result = Run(report, scene, events=_events_from_core(columns, len(job['masses'])))
    if interrupted:
        raise RunInterrupted(result) from None
    _warn_about_cap(result, max_collisions, simulate_to_cap, mode)
    return result


def predict(masses, positions, velocities, restitution=1.0, **options):
    """The model's answer alone (mode 'predict', no events): Run.prediction's dict."""
    options.update(mode='predict', events='none')
    return run(masses, positions, velocities, restitution, **options).prediction
