"""collision_lab.read_bag: a run that collision_lab_node recorded (docs/ros.md, Bags), as
the Run that collision_lab.run gives: the scene as run()'s keyword arguments, the summary
under run()'s keys, the prediction, and every CollisionEvent as numpy arrays, streamed
into columns (no message or per-event record kept)."""
import math
from array import array
from operator import attrgetter

import numpy as np

from ._run import (_BODY_ARRAYS, _MODEL_ARRAYS, _SCALARS, ESCALATION_KEYS, FULL_STATE_MAX_BODIES, SUMMARY_KEYS,
                   Run, body_name, events_from_records)

_MODES = {0: 'full', 1: 'predict', 2: 'summary'}
_KINDS = {0: 'impact', 1: 'collapse'}
_PAIRS_PREDICTED = {0: 'AB', 1: 'BC'}
_RESTITUTION_MODELS = {0: 'constant', 1: 'tc', 2: 'viscoelastic', 3: 'threshold'}
# core::kInfiniteRunDisplayCap: the impacts of an endless run (two walls, a box, a ring of
# ghosts) simulated without simulate_to_cap.
_INFINITE_RUN_DISPLAY_CAP = 1000
# The summary's keys that a bag holds (RunSummary and Prediction); read_bag gives the others
# of SUMMARY_KEYS as None.
BAG_SUMMARY_KEYS = ('model', 'model_reason', 'collision_count', 'simulated', 'truncated', 'cancelled',
                    'truncation_reason', 'stop_reason', 'predicted_collision_count', 'predicted_infinite',
                    'paper_predicted_collision_count', 'max_prediction_error', 'energy_lost',
                    'energy_relative_drift', 'momentum_relative_drift', 'compute_time_s', 'collapsed',
                    'collapse_time', 'collapse_position', 'cluster_impacts', 'rule_elastic_impacts',
                    'critical_restitution', 'spiral_angle', 'final_velocities', 'uncertified_values',
                    'time_beyond_range', 'predicted_final_velocities', 'max_possible_collision_count',
                    'predicted_first_pair', 'theta', 'alpha', 'omega', 'psi', 'paper_phi_bc')
# The bag's own summary keys: whose run, and where it was recorded.
BAG_ONLY_KEYS = ('run_id', 'student', 'bag_path')


def _value(x):
    """A float of a message as the CLI's JSON has it: NaN and infinities become None."""
    return None if isinstance(x, float) and not math.isfinite(x) else x


def _values(xs):
    return [_value(float(x)) for x in xs]


def _pair_name(index, seam=False):
    """The core's pairName: 'AB', ..., 'YZ', then 'Z-#26', '#26-#27', ...; across a ring's
    seam (seam) the last body's name and A's: 'EA', '#30-A' (io::eventPairName)."""
    if seam:
        return body_name(index) + ('' if index < 26 else '-') + body_name(0)
    return body_name(index) + ('' if index + 1 < 26 else '-') + body_name(index + 1)


_PAIR_ARRAYS = ('pair_velocities_before', 'pair_velocities_after', 'pair_energy_transfer')
_INT_SCALARS = ('index', 'pair_index', 'first_moved', 'last_moved')
# The float fields that _event writes as the CLI's JSON does (a non-finite value null, so NaN
# in the columns); time and position keep their value (an inf time stays inf).
_NULLED_FLOATS = ('restitution', 'energy_lost', 'total_energy', 'total_momentum')
_FLOATS = ('time', 'position') + _NULLED_FLOATS
_get_ints = attrgetter(*_INT_SCALARS)
_get_floats = attrgetter(*_FLOATS)


def _is_event(datatype):
    return datatype.split('/')[-1] == 'CollisionEvent'


def _nulled(values):
    """values with every non-finite value NaN (the JSON's null), in place."""
    np.copyto(values, np.nan, where=~np.isfinite(values))
    return values


class _EventColumns:
    """The event columns of a run's CollisionEvent messages, filled one message at a time
    (add) and handed over in events_from_records' layout (arrays), the same keys, dtypes and
    values: the scalars and the pair's fields in growing arrays of 8 bytes a value; the
    per-body arrays (and the three-body model's) in events x bodies arrays only for a scene
    of at most FULL_STATE_MAX_BODIES bodies, whose messages carry them. Above that the
    messages' arrays are empty and not read, and those columns are run()'s read-only view of
    one NaN (no events x bodies memory): Run.state_at rebuilds every body's state."""

    def __init__(self, bodies):
        self.bodies = bodies
        self.full_state = bodies <= FULL_STATE_MAX_BODIES
        self.count = 0
        # kind and pair: each event's number of its name (the names are few).
        self.kind_names, self.pair_names = {}, {}
        self.kinds, self.pairs = array('q'), array('q')
        # One row per event, interleaved: _INT_SCALARS; cluster_impact; _FLOATS; the pair's
        # fields (_PAIR_ARRAYS, two values each).
        self.ints, self.cluster, self.floats, self.pair = array('q'), array('B'), array('d'), array('d')
        self.uncertified = []  # per event, the names of its values not certified correctly rounded
        self.uncertified_names = {}
        # key -> the events' rows of `bodies` values, one after another (NaN where a message's
        # array is empty), from the first event whose message has that array.
        self.per_body = {}
        self.nan_row = array('d', [math.nan] * bodies)

    def add(self, msg):
        kind = self.kind_names.get(msg.kind)
        if kind is None:
            kind = self.kind_names[msg.kind] = len(self.kind_names)
        # Only an impact across a ring's seam has last_moved below its pair_index.
        seam = msg.kind == 0 and msg.last_moved < msg.pair_index
        pair = self.pair_names.get((msg.pair_index, seam))
        if pair is None:
            pair = self.pair_names[(msg.pair_index, seam)] = len(self.pair_names)
        self.kinds.append(kind)
        self.pairs.append(pair)
        self.ints.extend(_get_ints(msg))
        self.cluster.append(bool(msg.cluster_impact))
        self.floats.extend(_get_floats(msg))
        values = self.pair
        values.extend(msg.pair_velocities_before)
        values.extend(msg.pair_velocities_after)
        values.extend(msg.pair_energy_transfer)
        uncertified = getattr(msg, 'uncertified', ())
        if len(uncertified):
            # One tuple for every event with the same names (a long run's events share a few).
            names = tuple(uncertified)
            self.uncertified.append(self.uncertified_names.setdefault(names, names))
        else:
            self.uncertified.append(())
        if self.full_state:
            bodies, per_body = self.bodies, self.per_body
            for key in _BODY_ARRAYS + _MODEL_ARRAYS:
                values = getattr(msg, key)
                rows = per_body.get(key)
                if len(values):
                    if rows is None:  # NaN in the events before
                        rows = per_body[key] = self.nan_row * self.count
                    if len(values) > bodies:
                        raise ValueError('CollisionEvent %d: %s has %d values for %d bodies'
                                         % (msg.index, key, len(values), bodies))
                    rows.extend(values)
                    if len(values) < bodies:  # NaN after a short row, as events_from_records
                        rows.extend(self.nan_row[len(values):])
                elif rows is not None:
                    rows.extend(self.nan_row)
        self.count += 1

    def _rows(self, key):
        """The events x bodies array of key (NaN where an event had none), or None when no
        event had one."""
        rows = self.per_body.pop(key, None)
        if rows is None:
            return None
        return _nulled(np.frombuffer(rows, dtype=float).reshape(self.count, self.bodies))

    def arrays(self):
        """The columns, as events_from_records gives them for the same events."""
        n, bodies = self.count, self.bodies
        if n == 0:
            return events_from_records([], bodies)
        kinds = np.array([_KINDS.get(kind, str(kind)) for kind in self.kind_names], dtype=str)
        pairs = np.array([_pair_name(index, seam) for index, seam in self.pair_names], dtype=str)
        arrays = {'kind': kinds[np.frombuffer(self.kinds, dtype=np.int64)],
                  'pair': pairs[np.frombuffer(self.pairs, dtype=np.int64)]}
        self.kinds = self.pairs = None
        ints = np.frombuffer(self.ints, dtype=np.int64).reshape(n, len(_INT_SCALARS))
        floats = np.frombuffer(self.floats, dtype=float).reshape(n, len(_FLOATS))
        for key, dtype in _SCALARS:
            if key in _INT_SCALARS:
                column = ints[:, _INT_SCALARS.index(key)].copy()
            elif key == 'cluster_impact':
                column = np.frombuffer(self.cluster, dtype=np.uint8).astype(bool)
            else:
                column = floats[:, _FLOATS.index(key)].copy()
                if key in _NULLED_FLOATS:
                    _nulled(column)
            arrays[key] = column.astype(dtype, copy=False)
        del ints, floats
        self.ints = self.cluster = self.floats = None
        for key in _BODY_ARRAYS:
            rows = self._rows(key)
            arrays[key] = rows if rows is not None else np.broadcast_to(np.float64(np.nan), (n, bodies))
        pair = np.frombuffer(self.pair, dtype=float).reshape(n, len(_PAIR_ARRAYS), 2)
        for i, key in enumerate(_PAIR_ARRAYS):
            arrays[key] = _nulled(pair[:, i].copy())
        del pair
        self.pair = None
        for key in _MODEL_ARRAYS:
            rows = self._rows(key)
            if rows is not None:
                arrays[key] = rows
        uncertified = np.empty(n, dtype=object)
        for j, names in enumerate(self.uncertified):
            uncertified[j] = names
        self.uncertified = None
        arrays['uncertified'] = uncertified
        return arrays


def _scene(initial):
    masses = list(initial.masses)
    return {'name': initial.run_id, 'description': '', 'bodies': len(masses),
            'walls': [body_name(i) for i, m in enumerate(masses) if math.isinf(m)],
            'masses': _values(masses), 'positions': _values(initial.positions),
            'velocities': _values(initial.velocities), 'restitution': _values(initial.restitution)}


def _simulated_to_cap(msg, cap):
    """Whether the node ran with ~simulate_to_cap, which the bag does not record: true where
    the summary shows it (simulated although the model predicted more impacts than the cap,
    or an endless run simulated past the display cap); otherwise false, which gives the same
    run (the option changes nothing else)."""
    if msg is None or not msg.simulated:
        return False
    if msg.predicted_collision_count_defined and msg.predicted_collision_count > cap:
        return True
    return bool(msg.infinite_collisions) and msg.collision_count > _INFINITE_RUN_DISPLAY_CAP


def _run_scene(initial, parameters, summary):
    """run()'s keyword arguments for the run the bag holds (Run.scene): the scene and its
    options from InitialConditions, the cap the run used from RunParameters, and the events
    the node asked of the core (all in full mode, none otherwise)."""
    model = _RESTITUTION_MODELS.get(initial.restitution_model, str(initial.restitution_model))
    restitution = [float(e) for e in initial.restitution]
    if parameters is not None:
        cap = parameters.max_collisions
    else:  # a bag older than RunParameters (0.5.0): the input's cap, or the node's default
        cap = initial.max_collisions or 10_000_000
    mode = _MODES.get(initial.mode, str(initial.mode))
    return {'name': initial.run_id, 'masses': [float(m) for m in initial.masses],
            'positions': [float(x) for x in initial.positions],
            'velocities': [float(v) for v in initial.velocities],
            # Empty: elastic (run()'s 1.0); one value: every pair's.
            'restitution': 1.0 if not restitution else (restitution[0] if len(restitution) == 1 else restitution),
            'ring': float(initial.ring) if initial.ring else None, 'restitution_model': model,
            'tc': float(initial.tc) if model == 'tc' else None,
            'elastic_below': float(initial.elastic_below) if model == 'threshold' else None,
            'viscoelastic_speed': float(initial.viscoelastic_speed) if model == 'viscoelastic' else None,
            'max_collisions': int(cap), 'simulate_to_cap': _simulated_to_cap(summary, cap), 'mode': mode,
            'events': 'all' if mode == 'full' else 'none', 'full_state_every': 1}


def _summary(msg, prediction):
    """RunSummary (and Prediction's values) under run()'s summary keys (SUMMARY_KEYS, then
    BAG_ONLY_KEYS); the keys the bag does not hold (not in BAG_SUMMARY_KEYS) are None."""
    def defined(value, flag):
        return value if flag else None

    summary = dict.fromkeys(SUMMARY_KEYS)
    summary['escalation'] = dict.fromkeys(ESCALATION_KEYS)
    summary.update({
        'model': msg.model_name, 'model_reason': msg.model_reason,
        'collision_count': msg.collision_count, 'simulated': msg.simulated,
        'truncated': msg.truncated, 'cancelled': msg.cancelled,
        'truncation_reason': msg.truncation_reason, 'stop_reason': msg.stop_reason,
        'predicted_collision_count': defined(msg.predicted_collision_count, msg.predicted_collision_count_defined),
        'predicted_infinite': msg.infinite_collisions,
        'paper_predicted_collision_count': defined(msg.paper_predicted_collision_count,
                                                   msg.paper_predicted_collision_count_defined),
        'max_prediction_error': _value(msg.max_prediction_error),
        'energy_lost': _value(msg.energy_lost),
        'energy_relative_drift': _value(msg.energy_relative_drift),
        'momentum_relative_drift': _value(msg.momentum_relative_drift),
        'compute_time_s': msg.compute_time, 'collapsed': msg.collapsed,
        'collapse_time': _value(msg.collapse_time), 'collapse_position': _value(msg.collapse_position),
        'cluster_impacts': msg.cluster_impacts, 'rule_elastic_impacts': msg.rule_elastic_impacts,
        'critical_restitution': _value(msg.critical_restitution),
        'spiral_angle': _value(msg.spiral_angle),
        'final_velocities': _values(msg.final_velocities),
        'uncertified_values': list(getattr(msg, 'uncertified_values', [])),
        'time_beyond_range': bool(getattr(msg, 'time_beyond_range', False))})
    if prediction is not None:
        # Empty when the model gives none: the CLI's null.
        summary['predicted_final_velocities'] = _values(prediction.final_velocities) or None
        summary['max_possible_collision_count'] = prediction.max_possible_collision_count
        summary['predicted_first_pair'] = _PAIRS_PREDICTED.get(prediction.first_pair_index)
        # The rotation model's angles [rad] (NaN, not given: None).
        summary.update(theta=_value(prediction.theta), alpha=_value(prediction.alpha),
                       omega=_value(prediction.omega), psi=_value(prediction.psi),
                       paper_phi_bc=_value(prediction.phi_bc))
    summary.update(run_id=msg.run_id, student=msg.student, bag_path=msg.bag_path)
    return summary


def read_bag(path):
    """The run recorded in the bag at `path` (one run per bag, as collision_lab_node writes
    them) as a Run. Needs python3-rosbag (imported here, not with the module).

    scene: run()'s keyword arguments (SCENE_KEYS) from InitialConditions (the scene, the
    restitution model, the ring), RunParameters (the cap the run used) and RunSummary
    (simulate_to_cap, which the bag does not record, where the summary shows it), so that
    run(**read_bag(path).scene) runs the recorded scene again: the same collision count and
    final velocities, bit for bit (a run that the node's service limits stopped aside).
    report['scene']: the CLI's descriptive scene (name, description, bodies, walls, ...).
    summary: exactly run()'s keys (SUMMARY_KEYS) plus run_id, student and bag_path, from
    RunSummary and Prediction; the keys the bag does not hold (not in BAG_SUMMARY_KEYS) are
    None. events: every CollisionEvent, the arrays of run(). options: as run()'s.

    The events are streamed: one pass over the CollisionEvent messages fills the columns
    (8 bytes a value), keeping no message. Above CollisionEvent.FULL_STATE_MAX_BODIES (64)
    bodies the messages carry the pair's fields only: the per-body arrays (positions,
    velocities_after, ...) are then run()'s read-only view of one NaN (no events x bodies
    memory), and state_at(k) or state_at(t=...) gives every body's position and velocity,
    rebuilt from the pair fields as for run()'s runs; to_pandas() then leaves out the
    v_/x_ columns, and to_pandas(bodies=[...]) gives those of the bodies named.
    """
    import rosbag
    initial = prediction = summary = parameters = None
    with rosbag.Bag(path) as bag:
        # The run's few messages first (the scene decides the events' layout), then the
        # events in one pass.
        for _, msg, _ in bag.read_messages(connection_filter=lambda topic, datatype, *_: not _is_event(datatype)):
            kind = msg._type.split('/')[-1]
            if kind == 'InitialConditions':
                initial = msg
            elif kind == 'Prediction':
                prediction = msg
            elif kind == 'RunSummary':
                summary = msg
            elif kind == 'RunParameters':
                parameters = msg
        if initial is None:
            raise ValueError('%s: no InitialConditions: not a bag of collision_lab_node' % path)
        events = _EventColumns(len(initial.masses))
        for _, msg, _ in bag.read_messages(connection_filter=lambda topic, datatype, *_: _is_event(datatype)):
            events.add(msg)
    scene = _run_scene(initial, parameters, summary)
    report = {'scene': _scene(initial),
              'options': {'max_collisions': scene['max_collisions'], 'events': scene['events'],
                          'mode': scene['mode']},
              'units': {'mass': 'kg', 'position': 'm', 'velocity': 'm/s', 'time': 's', 'energy': 'J',
                        'momentum': 'kg m/s'},
              'summary': _summary(summary, prediction) if summary is not None else {}}
    return Run(report, scene, report['summary'], events.arrays())
