"""Events with bounded memory: a run's events are columns filled in C++ (no JSON text), and a
scene of more than 64 bodies keeps no events x bodies arrays, so a long run of many bodies
fits in memory with every event recorded."""
import os
import subprocess
import sys

import numpy as np

# 2,000 equal masses, velocities uniform in [-1, 1] (seeded): about a million impacts.
_SCENE = '''
import resource
import numpy as np
import collision_lab
n = 2000
velocities = np.random.default_rng(1).uniform(-1, 1, n)
run = collision_lab.run([1.0] * n, list(range(n, 0, -1)), velocities)
print(run.summary['collision_count'], len(run.events['time']), run.events['pair_velocities_after'].shape[0],
      resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
'''


def test_two_thousand_equal_masses_with_every_event_take_under_1_5_gb():
    out = subprocess.run([sys.executable, '-c', _SCENE], env=os.environ, capture_output=True, text=True,
                         check=True).stdout.split()
    count, events, pair_rows, peak_kib = (int(word) for word in out)
    # Equal masses exchange velocities: each pair whose velocities are out of order (the
    # right body slower than the left one) meets once, and no other pair does.
    v = np.random.default_rng(1).uniform(-1, 1, 2000)
    inversions = int(sum(np.count_nonzero(v[i] < v[i + 1:]) for i in range(len(v))))
    assert count == events == pair_rows == inversions
    assert peak_kib * 1024 < 1.5e9, '%.2f GB' % (peak_kib * 1024 / 1e9)
