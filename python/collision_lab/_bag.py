"""collision_lab.read_bag: a run that collision_lab_node recorded (docs/ros.md, Bags), as
the Run that collision_lab.run gives: the scene, the summary's keys that the bag holds, the
prediction, and every CollisionEvent as numpy arrays."""
import math

from ._run import Run, body_name

_MODES = {0: 'full', 1: 'predict', 2: 'summary'}
_KINDS = {0: 'impact', 1: 'collapse'}
_PAIRS_PREDICTED = {0: 'AB', 1: 'BC'}


def _value(x):
    """A float of a message as the CLI's JSON has it: NaN and infinities become None."""
    return None if isinstance(x, float) and not math.isfinite(x) else x


def _values(xs):
    return [_value(float(x)) for x in xs]


def _pair_name(index):
    """The core's pairName: 'AB', ..., 'YZ', then 'Z-#26', '#26-#27', ..."""
    return body_name(index) + ('' if index + 1 < 26 else '-') + body_name(index + 1)


def _event(msg):
    """A CollisionEvent as the CLI's JSON event (per-body arrays empty beyond the message's
    FULL_STATE_MAX_BODIES: None)."""
    event = {'kind': _KINDS.get(msg.kind, str(msg.kind)), 'index': msg.index,
             'pair': _pair_name(msg.pair_index), 'pair_index': msg.pair_index,
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


def _summary(msg, prediction):
    """RunSummary (and Prediction's final velocities) under the CLI's summary keys."""
    def defined(value, flag):
        return value if flag else None

    summary = {'model': msg.model_name, 'model_reason': msg.model_reason,
               'collision_count': msg.collision_count, 'simulated': msg.simulated,
               'truncated': msg.truncated, 'cancelled': msg.cancelled,
               'truncation_reason': msg.truncation_reason, 'stop_reason': msg.stop_reason,
               'predicted_collision_count': defined(msg.predicted_collision_count,
                                                    msg.predicted_collision_count_defined),
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
               'time_beyond_range': bool(getattr(msg, 'time_beyond_range', False)),
               # The bag's own: whose run, and where it was recorded.
               'run_id': msg.run_id, 'student': msg.student, 'bag_path': msg.bag_path}
    if prediction is not None:
        # Empty when the model gives none: the CLI's null.
        summary['predicted_final_velocities'] = _values(prediction.final_velocities) or None
        summary['max_possible_collision_count'] = prediction.max_possible_collision_count
        summary['predicted_first_pair'] = _PAIRS_PREDICTED.get(prediction.first_pair_index)
    return summary


def read_bag(path):
    """The run recorded in the bag at `path` (one run per bag, as collision_lab_node writes
    them) as a Run: scene and initial state from InitialConditions, summary from RunSummary
    (the CLI's keys; plus run_id, student, bag_path), events from every CollisionEvent,
    options from RunParameters. Needs python3-rosbag (imported here, not with the module)."""
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
    report = {'scene': _scene(initial),
              'options': {'max_collisions': parameters.max_collisions if parameters else initial.max_collisions,
                          'events': 'all', 'mode': _MODES.get(initial.mode, str(initial.mode))},
              'units': {'mass': 'kg', 'position': 'm', 'velocity': 'm/s', 'time': 's', 'energy': 'J',
                        'momentum': 'kg m/s'},
              'events': [_event(msg) for msg in events],
              'summary': _summary(summary, prediction) if summary is not None else {}}
    return Run(report, list(initial.masses), list(initial.positions), list(initial.velocities))
