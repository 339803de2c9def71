#!/usr/bin/env python3
"""Writes config/gas_1000.csv, the 1,000-body random gas preset (scenarios.yaml: gas_1000),
or with --box config/granular_box_1000.csv (granular_box_1000): the same bodies between two
walls at rest, 1 m beyond the outermost bodies (x = 1000 m and x = -1 m).

Seeded, so the file is the same on every machine (Python's random.Random is Mersenne
Twister, stable across versions): masses uniform in [1, 2] kg, velocities uniform in
[-1, 1] m/s, spacing 1 m, listed right to left (x = 999, 998, ..., 0 m). Numbers are
written in their shortest round-trip form, so the file holds the exact doubles.

    python3 config/generate_gas.py > config/gas_1000.csv
    python3 config/generate_gas.py --box > config/granular_box_1000.csv
"""
import random
import sys

N, SEED = 1000, 1000
box = sys.argv[1:] == ["--box"]
rng = random.Random(SEED)
print("mass,position,velocity")
if box:
    print(f"inf,{float(N)!r},0.0")
for i in range(N):
    mass = 1.0 + rng.random()
    velocity = 2.0 * rng.random() - 1.0
    print(f"{mass!r},{float(N - 1 - i)!r},{velocity!r}")
if box:
    print("inf,-1.0,0.0")
