"""SceneError: the CLI's JSON error of a rejected scene or option, field for field."""
import pytest

import collision_lab

NAN = float('nan')

BAD = [
    (dict(masses=[1, 1, 1], positions=[2, 2, 0], velocities=[0, 0, 0]),
     '--masses 1,1,1 --positions 2,2,0 --velocities 0,0,0', 'POSITIONS_COINCIDENT', 'positions'),
    (dict(masses=[1, -1, 1], positions=[2, 1, 0], velocities=[0, 0, 0]),
     '--masses 1,-1,1 --positions 2,1,0 --velocities 0,0,0', None, 'masses[1]'),
    (dict(masses=[1, NAN, 1], positions=[2, 1, 0], velocities=[0, 0, 0]),
     '--masses 1,nan,1 --positions 2,1,0 --velocities 0,0,0', 'NON_FINITE_VALUE', 'masses[1]'),
    (dict(masses=[1, 1, 1], positions=[2, 1, 0], velocities=[-1, 0, 1]),
     '--masses 1,1,1 --positions 2,1,0 --velocities -1,0,1', 'TRIPLE_COLLISION', None),
    (dict(masses=[1, 1], positions=[1, 0], velocities=[0, 0], restitution=1.5),
     '--masses 1,1 --positions 1,0 --velocities 0,0 --restitution 1.5', None, None),
    (dict(masses=[1, 1], positions=[1, 0], velocities=[0, 0], events='sometimes'),
     '--masses 1,1 --positions 1,0 --velocities 0,0 --events sometimes', 'INVALID_OPTION', 'events'),
    (dict(masses=[1, 1], positions=[1, 0], velocities=[0, 0], tc=1e-3),
     '--masses 1,1 --positions 1,0 --velocities 0,0 --tc 0.001', 'USAGE', 'tc'),
]


@pytest.mark.parametrize('kwargs,cli_args,reason,field', BAD)
def test_scene_error_is_the_cli_json_error(cli, kwargs, cli_args, reason, field):
    expected = cli(cli_args.split())['error']
    with pytest.raises(collision_lab.SceneError) as raised:
        collision_lab.run(**kwargs)
    error = raised.value
    assert isinstance(error, ValueError)
    assert (error.reason, error.code, error.field, error.message) == (
        expected['reason'], expected['code'], expected['field'], expected['message'])
    assert reason is None or error.reason == reason
    assert field is None or error.field == field
    assert error.message in str(error)


def test_predict_raises_scene_error_too():
    with pytest.raises(collision_lab.SceneError) as raised:
        collision_lab.predict([1, 0, 1], [2, 1, 0], [0, 0, 0])
    assert raised.value.field == 'masses[1]'
