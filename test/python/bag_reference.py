"""The reference that the streamed read_bag is held to (issue 47): a CollisionEvent made the
CLI's JSON event, as read_bag built each event before it streamed them;
events_from_records([event_record(m) for m in messages], bodies) gives the columns that
read_bag's _EventColumns must give, bit for bit. And run_quietly, the bag tests' run()."""
import warnings

import collision_lab
from collision_lab._bag import _KINDS, _pair_name, _value, _values


def run_quietly(**scene):
    """run(**scene), its CapWarning (a scene over its cap, a ring stopped at it) not shown."""
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', collision_lab.CapWarning)
        return collision_lab.run(**scene)


def event_record(msg):
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

