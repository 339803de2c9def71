#!/usr/bin/env python3
"""Benchmark (not a test) of the Python module collision_lab: every figure is the median of
--repeats timings, each beside its baseline measured in the same process.

1. the binding's cost per run against the C++ call: collision_lab.run of a three-body scene
   (the pi billiard, M/m = 100: 31 impacts), wall time per call, against the summary's
   compute_time_s (the C++ run alone, inside the same call);
2. sweep throughput on every core against one core (collision_lab.sweep, workers=);
3. a Dask LocalCluster of 2 worker processes (1 thread each, TCP) against local threads
   (workers=2) on the same sweep;
4. the wall time of notebook 3's 512 x 512 grid (mode predict).

Run after sourcing the workspace:  python3 bench/python/bench_python.py
"""
import argparse
import math
import os
import statistics
import time

import numpy as np

import collision_lab as cl


def median_time(action, repeats):
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        action()
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def three_body_scenes(count):
    """count three-body elastic scenes of random masses (seeded): 2 to ~60 impacts each."""
    rng = np.random.default_rng(2024)
    return [dict(masses=list(10.0 ** rng.uniform(-1, 2, 3)), positions=[2, 1, 0], velocities=[-1, 0, 0])
            for _ in range(count)]


def binding_cost(repeats, calls):
    for events in ('all', 'none'):
        per_call, compute = [], []
        for _ in range(repeats):
            inner = []
            started = time.perf_counter()
            for _ in range(calls):
                inner.append(cl.run([100, 1, math.inf], [2, 1, 0], [-1, 0, 0], events=events).summary['compute_time_s'])
            per_call.append((time.perf_counter() - started) / calls)
            compute.append(statistics.median(inner))
        wall, core = statistics.median(per_call), statistics.median(compute)
        print('binding, pi billiard (31 impacts), events=%-4s: %7.1f us a call; C++ run (compute_time_s) %6.1f us; '
              'ratio %.1fx' % (events, wall * 1e6, core * 1e6, wall / core))


def sweep_cores(repeats, scenes):
    cores = os.cpu_count() or 1
    one = median_time(lambda: cl.sweep(scenes, workers=1), repeats)
    every = median_time(lambda: cl.sweep(scenes, workers=cores), repeats)
    print('sweep of %d three-body scenes: 1 core %.2f s (%.0f scenes/s); %d cores %.2f s (%.0f scenes/s); '
          'speed-up %.2fx' % (len(scenes), one, len(scenes) / one, cores, every, len(scenes) / every, one / every))


def sweep_dask(repeats, scenes):
    from dask.distributed import Client, LocalCluster
    local = median_time(lambda: cl.sweep(scenes, workers=2), repeats)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        cl.sweep(scenes[:100], client=client)  # the workers import collision_lab once, outside the timing
        remote = median_time(lambda: cl.sweep(scenes, client=client), repeats)
        same = cl.sweep(scenes, client=client).drop(columns='compute_time_s').equals(
            cl.sweep(scenes, workers=2).drop(columns='compute_time_s'))
    print('sweep of %d scenes: local threads (workers=2) %.2f s; Dask LocalCluster, 2 processes x 1 thread %.2f s; '
          'ratio %.2fx; tables equal: %s' % (len(scenes), local, remote, remote / local, same))


def mass_plane(repeats, side):
    ratios = np.geomspace(1e-2, 1e3, side)

    def grid():
        return cl.sweep(grid={'a_over_b': ratios, 'c_over_b': ratios},
                        base=lambda p: dict(masses=[p['a_over_b'], 1.0, p['c_over_b']], positions=[2, 1, 0],
                                            velocities=[-1, 0, 0]), mode='predict')
    wall = median_time(grid, repeats)
    print('%d x %d mass-plane grid (mode predict, every core): %.1f s, %.0f us a scene'
          % (side, side, wall, wall / side ** 2 * 1e6))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--repeats', type=int, default=5, help='timings per figure; the median is printed')
    parser.add_argument('--scenes', type=int, default=20000, help='scenes in the sweeps')
    parser.add_argument('--side', type=int, default=512, help='side of the mass-plane grid')
    args = parser.parse_args()
    print('collision_lab benchmark: %d cores, load average %.2f %.2f %.2f; medians of %d'
          % ((os.cpu_count() or 1,) + os.getloadavg() + (args.repeats,)))
    binding_cost(args.repeats, calls=200)
    scenes = three_body_scenes(args.scenes)
    sweep_cores(args.repeats, scenes)
    sweep_dask(args.repeats, scenes)
    mass_plane(args.repeats, args.side)
    print('load average at the end: %.2f %.2f %.2f' % os.getloadavg())


if __name__ == '__main__':
    main()
