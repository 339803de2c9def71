"""Ctrl-C during a run: the engine's cancel flag stops it and RunInterrupted (a
KeyboardInterrupt) is raised with the run as far as it went; the GIL is free while a run goes
on. The run would take hours uncancelled (3.1e10 impacts),
so returning at all is the check."""
import _thread
import os
import signal
import threading

import pytest

import collision_lab

INF = float('inf')


@pytest.fixture(autouse=True)
def ctrl_c_raises():
    """Python's own SIGINT handler, also where the test was started with SIGINT ignored (a
    background job of a script), which Python would keep."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def long_run(events='none'):
    # m_A/m_B = 1e20: 31,415,926,535 impacts, simulated one by one up to the cap.
    collision_lab.run([1e20, 1, INF], [2, 1, 0], [-1, 0, 0], simulate_to_cap=True, events=events,
                      max_collisions=10 ** 12)


@pytest.mark.parametrize('interrupt', [_thread.interrupt_main, lambda: os.kill(os.getpid(), signal.SIGINT)],
                         ids=['interrupt_main', 'SIGINT'])
def test_ctrl_c_cancels_a_long_run(interrupt):
    timer = threading.Timer(0.5, interrupt)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            long_run()
    finally:
        timer.cancel()
    # The module still works afterwards.
    assert collision_lab.run([100, 1, INF], [2, 1, 0], [-1, 0, 0]).summary['collision_count'] == 31


def test_a_stopped_run_gives_what_it_simulated():
    # Two balls (1 and 2 kg) between walls 3 m apart bounce forever: the engine walks the
    # impacts one by one until Ctrl-C.
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(collision_lab.RunInterrupted) as stopped:
            collision_lab.run([INF, 1, 2, INF], [3, 2, 1, 0], [0, 1, -1, 0], simulate_to_cap=True,
                              events='first:1000', max_collisions=10 ** 12)
    finally:
        timer.cancel()
    run = stopped.value.run
    s = run.summary
    assert s['cancelled'] is True and s['truncated'] is True
    assert s['collision_count'] > 1000  # half a second of a run with no end
    assert len(run.events['index']) == 1000  # the first 1,000 impacts, as asked
    # Elastic, walls at rest: the energy at the stop is the start's, 1/2 + 1 = 1.5 J.
    v = s['final_velocities']
    assert abs((1 * v[1] ** 2 + 2 * v[2] ** 2) / 2 - 1.5) <= 1e-12


def test_a_stopped_run_crosses_processes():
    # RunInterrupted pickles (a pool's worker stopped by Ctrl-C hands it to the parent).
    import pickle
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    try:
        with pytest.raises(collision_lab.RunInterrupted) as stopped:
            long_run()
    finally:
        timer.cancel()
    again = pickle.loads(pickle.dumps(stopped.value))
    assert isinstance(again, collision_lab.RunInterrupted)
    assert again.run.summary['cancelled'] is True


def test_another_signal_handlers_exception_is_kept():
    # A SIGALRM handler that raises TimeoutError (a test timeout) stops the run too, and its
    # exception, not RunInterrupted, reaches the caller.
    def timeout(signum, frame):
        raise TimeoutError('too slow')
    previous = signal.signal(signal.SIGALRM, timeout)
    signal.setitimer(signal.ITIMER_REAL, 0.3)
    try:
        with pytest.raises(TimeoutError):
            long_run()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def test_ctrl_c_cancels_a_sweep():
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    scene = dict(masses=[1e20, 1, INF], positions=[2, 1, 0], velocities=[-1, 0, 0])
    try:
        with pytest.raises(KeyboardInterrupt):
            collision_lab.sweep([scene] * 4, workers=2, simulate_to_cap=True, max_collisions=10 ** 12)
    finally:
        timer.cancel()


def test_the_gil_is_released_during_a_run():
    # Another Python thread counts to 100,000 (bytecode: it needs the GIL) and only then
    # interrupts the run. Were the GIL held during the run, it could not count, and the run
    # of 3.1e10 impacts would not end.
    counted = []

    def count_then_interrupt():
        count = 0
        for _ in range(100_000):
            count += 1
        counted.append(count)
        _thread.interrupt_main()

    helper = threading.Timer(0.2, count_then_interrupt)
    helper.start()
    with pytest.raises(KeyboardInterrupt):
        long_run()
    helper.join()
    assert counted == [100_000]
