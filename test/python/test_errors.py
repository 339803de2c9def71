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


# Options in run()'s words: its keywords, not the CLI's options (the reasons and codes are the
# CLI's), and TypeError / ValueError where Python would raise them.
OPTIONS = [
    (dict(tc=1e-3), '--tc 0.001', 'tc', "tc= belongs to restitution_model='tc'"),
    (dict(max_collisions=-1), '--max-collisions -1', 'max_collisions', 'max_collisions must be >= 0'),
    (dict(restitution=[]), '--restitution 0.5,0.5,0.5', 'restitution', 'restitution is empty'),
    (dict(events='sometimes'), '--events sometimes', 'events', "events must be 'all', 'none' or 'first:N'"),
    (dict(events='first:-1'), '--events first:-1', 'events', "events must be 'all', 'none' or 'first:N'"),
    (dict(mode='fast'), '--mode fast', 'mode', "mode must be 'full', 'predict' or 'summary'"),
    (dict(full_state_every=0), '--full-state-every 0', 'full_state_every', 'full_state_every must be >= 1'),
    (dict(max_collisions=2 ** 64), '--max-collisions 18446744073709551616', 'max_collisions',
     'max_collisions is too large'),
    (dict(restitution_model='sticky'), '--restitution-model sticky', 'restitution_model',
     "restitution_model must be 'constant', 'tc', 'threshold' or 'viscoelastic'"),
    (dict(temperature_csv='t.csv', mode='predict'), '--temperature-csv t.csv --mode predict', 'temperature_csv',
     "T(t) needs the simulation's impacts: mode='full'"),
]


@pytest.mark.parametrize('kwargs,cli_args,field,words', OPTIONS)
def test_options_are_named_as_run_names_them(cli, kwargs, cli_args, field, words):
    scene = dict(masses=[1, 1], positions=[1, 0], velocities=[0, 0])
    expected = cli(('--masses 1,1 --positions 1,0 --velocities 0,0 ' + cli_args).split())['error']
    with pytest.raises(collision_lab.SceneError) as raised:
        collision_lab.run(**scene, **kwargs)
    assert raised.value.field == field
    assert words in raised.value.message
    assert '--' not in raised.value.message
    if field != 'restitution':  # the CLI cannot be given an empty list
        assert (raised.value.reason, raised.value.code) == (expected['reason'], expected['code'])


def test_python_errors_for_python_mistakes():
    inf = float('inf')
    with pytest.raises(TypeError, match='max_collisions must be a whole number'):
        collision_lab.run([100, 1, inf], [2, 1, 0], [-1, 0, 0], max_collisions=2.5)
    with pytest.raises(TypeError, match='not True or False'):
        collision_lab.run([True, 1, inf], [2, 1, 0], [-1, 0, 0])
    with pytest.raises(ValueError, match=r'shape \(3, 1\)'):
        collision_lab.run([[100], [1], [inf]], [2, 1, 0], [-1, 0, 0])
    with pytest.raises(ValueError, match='masses is empty'):
        collision_lab.run([], [], [])
