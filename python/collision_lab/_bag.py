"""collision_lab.read_bag: a run that collision_lab_node recorded (docs/ros.md, Bags), as
the Run that collision_lab.run gives: the scene as run()'s keyword arguments, the summary
under run()'s keys, the prediction, and every CollisionEvent as numpy arrays."""
import math

from ._run import ESCALATION_KEYS, SUMMARY_KEYS, Run, body_name, events_from_records

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


def _event(msg):
    """A CollisionEvent as the CLI's JSON event (per-body arrays empty beyond the message's
    FULL_STATE_MAX_BODIES: None)."""
    kind = _KINDS.get(msg.kind, str(msg.kind))
    # Only an impact across a ring's seam has last_moved below its pair_index.
    seam = kind == 'impact' and msg.last_moved < msg.pair_index
    event = {'kind': kind, 'index': msg.index,
             'pair': _pair_name(msg.pair_index, seam), 'pair_index': msg.pair_index,
             'time': msg.time, 'position': msg.position, 'restitution': _value(msg.restitution),
             'first_moved': msg.first_moved, 'last_moved': msg.last_moved,
             'cluster_impact': msg.cluster_impact,
             'pair_velocities_before': _values(msg.pair_velocities_before),
             'pair_velocities_after': _values(msg.pair_velocities_after),
             'pair_energy_transfer': _values(msg.pair_energy_transfer),
             'energy_lost': _value(msg.energy_lost), 'total_energy': _value(msg.total_energy),
             'total_momentum': _value(msg.total_momentum),
             'uncertified': list(getattr(msg, 'uncertified', []))}
    for key in ('positions', 'velocities_before', 'velocities_after', 'energy_transfer',
                'kinetic_energy_after', 'predicted_velocities_after', 'paper_velocities_after',
                'predicted_energy_transfer', 'paper_energy_transfer'):
        values = getattr(msg, key)
        event[key] = _values(values) if len(values) else None
    return event


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
    """
    import rosbag
    initial = prediction = summary = parameters = None
    events = []
    with rosbag.Bag(path) as bag:
        for _, msg, _ in bag.read_messages():
            kind = msg._type.split('/')[-1]
            if kind == 'InitialConditions':
                initial = msg
            elif kind == 'Prediction':
                prediction = msg
            elif kind == 'RunSummary':
                summary = msg
            elif kind == 'RunParameters':
                parameters = msg
            elif kind == 'CollisionEvent':
                events.append(msg)
    if initial is None:
        raise ValueError('%s: no InitialConditions: not a bag of collision_lab_node' % path)
    scene = _run_scene(initial, parameters, summary)
    report = {'scene': _scene(initial),
              'options': {'max_collisions': scene['max_collisions'], 'events': scene['events'],
                          'mode': scene['mode']},
              'units': {'mass': 'kg', 'position': 'm', 'velocity': 'm/s', 'time': 's', 'energy': 'J',
                        'momentum': 'kg m/s'},
              'summary': _summary(summary, prediction) if summary is not None else {}}
    return Run(report, scene, report['summary'], events_from_records([_event(msg) for msg in events],
                                                                       len(scene['masses'])))
