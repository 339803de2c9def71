#!/usr/bin/env python3
"""Writes the seed corpora of fuzz/core_fuzzer.cpp (fuzz/corpus/core) and of
fuzz/nbody_fuzzer.cpp (fuzz/corpus/nbody), deterministically.

Each core seed is one scene from shared/physics.md's hard cases or the bad-input catalogue,
in the byte layout documented at the top of core_fuzzer.cpp (its bits 0-1, once the
working precision, now mean: bit 0 a visitor watches every event, bit 1 unused; the seeds
keep their bytes). Each N-body seed is a scene in nbody_fuzzer.cpp's layout: rings with
events (issue 32's crash among them), walls, per-pair restitution, the restitution models.
Run from anywhere:
    python3 fuzz/make_seeds.py
"""
import math
import os
import struct

INF, NAN = math.inf, math.nan
CAP = {0: 0, 1: 1, 2: 2, 3: 3, 5: 4, 10: 5, 100: 6, 1000: 7, 10000: 8, 100000: 9}
PRECISION = {"double": 0, "long_double": 1, "high": 2}
EVENTS = {"none": 0, "all": 1, "first3": 2}
MODE = {"full": 0, "predict_only": 1, "summary_only": 2}


def flags(precision="double", events="none", compact=False, skip_over_cap=False, mode="full"):
    return (PRECISION[precision] | EVENTS[events] << 2 | int(compact) << 4 | int(skip_over_cap) << 5
            | MODE[mode] << 6)


def raw(masses, positions, velocities, cap=100000, **options):
    """Any doubles, bit for bit."""
    header = bytes([flags(**options), CAP[cap]])
    return header + struct.pack("<9d", *masses, *positions, *velocities)


def compact_value(value):
    """(mantissa, exponent) with value == mantissa * 10^exponent as the fuzzer decodes it."""
    if math.isnan(value):
        return -32766, 0
    if math.isinf(value):
        return (-32768 if value > 0 else -32767), 0
    for exponent in range(-30, 31):
        mantissa = round(value / 10.0 ** exponent) if exponent >= 0 else round(value * 10 ** -exponent)
        if -32765 <= mantissa <= 32767:
            decoded = mantissa * 10.0 ** exponent if exponent >= 0 else mantissa / 10.0 ** -exponent
            if decoded == value:
                return mantissa, exponent
    raise ValueError(f"{value} has no compact form; use raw()")


def compact(masses, positions, velocities, cap=100000, **options):
    """Short decimal values (mantissa * 10^exponent), the form mutations explore best."""
    out = bytes([flags(compact=True, **options), CAP[cap]])
    for value in (*masses, *positions, *velocities):
        out += struct.pack("<hh", *compact_value(value))
    return out


SEEDS = {
    # Galperin's billiard: m_A / m_B = 100^(d-1), C a wall at rest: the digits of pi.
    "pi_31": compact((100, 1, INF), (2, 1, 0), (-1, 0, 0)),
    "pi_314_events": compact((1e4, 1, INF), (2, 1, 0), (-1, 0, 0), events="all", cap=1000),
    "pi_3141_high": compact((1e6, 1, INF), (2, 1, 0), (-1, 0, 0), precision="high", cap=10000),
    "pi_31415": compact((1e8, 1, INF), (2, 1, 0), (-1, 0, 0)),
    "pi_314159_truncated": compact((1e10, 1, INF), (2, 1, 0), (-1, 0, 0), skip_over_cap=True),
    "pi_wall_A": compact((INF, 1, 100), (2, 1, 0), (0, 0, 1)),
    "moving_wall": compact((INF, 1, 3), (5, 1, -2), (-2, 0, 1), events="first3"),
    # Kaleidoscopic masses (pi / alpha an integer): grazing last contacts.
    "kaleido_111": compact((1, 1, 1), (2, 1, 0), (-1, 0, 0), events="all"),
    "kaleido_213": compact((2, 1, 3), (2, 1, 0), (-1, 0, 0), precision="long_double"),
    "kaleido_519": compact((5, 1, 9), (2, 1, 0), (-1, 0, 0), precision="high", events="all"),
    "grazing_3_1_half": compact((3, 1, 0.5), (2, 1, 0), (-1, 0, 0), events="all"),
    "equal_three_collisions": compact((1, 1, 1), (3, 1, 0), (-1, 0, 1)),
    "paper_errata2": compact((1, 1, 1), (2, 1, 0), (-1, 0.3, 0.7), events="all"),
    "errata1_masses": compact((1, 2, 3), (1.5, 0.25, -4), (-2, 0.5, 1.5), mode="summary_only"),
    "bc_first": compact((2, 7, 1), (10, 1, 0), (0, 0, 5), events="all"),
    "nothing_collides": compact((1, 1, 1), (3, 2, 1), (3, 2, 1)),
    "common_velocity": compact((1, 1, 1), (3, 2, 1), (7, 7, 7)),
    # Near-triple: t_AB and t_BC differ in the last bit; and the exact triple (rejected).
    "near_triple": raw((1, 1, 1), (1 + 2 ** -52, 0, -1), (-1, 0, 1), events="all"),
    "near_triple_bc": raw((1, 3, 1), (1, 0, -1 - 2 ** -52), (-1, 0, 1)),
    "triple_exact": compact((1, 1, 1), (1, 0, -1), (-1, 0, 1)),
    # Extreme mass ratios and scales.
    "mass_1e12": compact((1e12, 1, 1e12), (2, 1, 0), (-1, 0, 0)),
    "mass_1e30": compact((1e30, 1, 1e30), (2, 1, 0), (-1, 0, 0), mode="predict_only"),
    "mass_1e300": raw((1e300, 1, 1e300), (2, 1, 0), (-1, 0, 0), mode="predict_only"),
    "mass_ratio_1e600": raw((1e300, 1e-300, 1e300), (2, 1, 0), (-1, 0, 0), mode="predict_only"),
    "mass_ratio_underflow": raw((1, 1e200, 1e-200), (2, 1, 0), (-1, 0, 0)),
    "subnormal_weighted": raw((1, 2.0 ** 128, 2.0 ** -12), (1e300, 0, -1), (-1e-300, 0, 0), events="all"),
    "max_possible_too_low": raw((1, 1e60, 1), (1e80, 1, 0), (-1e61, 0, 1), events="all"),
    "exact_escalation": raw((1e40, 1e17, 1e273), (3, 1, 0), (-1, 0, 1), mode="summary_only", cap=100),
    "subnormal_count": raw((1, 2, 0.26542376078465163), (3, 2, 1.5), (-5e-324, 0, 5e-324)),
    "light_count": raw((5, 1, 1e-200), (2, 1, 0), (-0.1, -0.1, 0), events="all"),
    "energy_transfer_overflow": raw((INF, 1e308, 3), (5, 1, 0), (0, 0, 1), events="all"),
    "light_outer": compact((1e-12, 1, 1e-12), (2, 1, 0), (-1, 0, 1)),
    "scale_1e150": raw((1e150, 1e150, 1e150), (3e150, 2e150, 1e150), (-1e-150, 0, 1e-150)),
    "scale_small": raw((1e-300, 2e-300, 3e-300), (3e-300, 2e-300, 1e-300), (-5e-324, 0, 5e-324)),
    "overflow_energy": raw((1e300, 1, 1), (2, 1, 0), (-1e10, 0, 0)),
    "time_overflow": raw((1, 1, 1), (1e300, 0, -1), (-1e-300, 0, 0), events="all"),
    "position_overflow": raw((1, 1, 1), (1, 0, -1e300), (1e10, 0, 1), events="all"),
    "velocity_near_max": raw((1, 1, 1), (2, 1, 0), (-1e308, 0, 1e308)),
    # Bad input: each is rejected by validate().
    "nan_mass": compact((NAN, 1, 1), (2, 1, 0), (-1, 0, 0)),
    "zero_mass": compact((1, 0, 1), (2, 1, 0), (-1, 0, 0)),
    "negative_mass": compact((1, -1, 1), (2, 1, 0), (-1, 0, 0)),
    "negative_zero_mass": raw((1, -0.0, 1), (2, 1, 0), (-1, 0, 0)),
    "two_walls": compact((INF, 1, INF), (2, 1, 0), (-1, 0, 0)),
    "infinite_b": compact((1, INF, 1), (2, 1, 0), (-1, 0, 0)),
    "nan_position": compact((1, 1, 1), (2, NAN, 0), (-1, 0, 0)),
    "inf_velocity": compact((1, 1, 1), (2, 1, 0), (-INF, 0, 0)),
    "unordered": compact((1, 1, 1), (0, 1, 2), (-1, 0, 0)),
    "coincident": compact((1, 1, 1), (1, 1, 0), (-1, 0, 0)),
    "gap_overflow": raw((1, 1, 1), (1.7e308, 0, -1.7e308), (-1, 0, 0)),
}


NBODY_EVENTS = {"none": 0, "all": 1, "first3": 2}
NBODY_MODEL = {"constant": 0, "tc": 1, "threshold": 2, "viscoelastic": 3}
NBODY_CAP = {0: 0, 1: 1, 10: 2, 100: 3, 1500: 4}


def nbody(masses, positions, velocities, restitution=(1.0,), ring=None, model="constant", parameter=None,
          events="all", cap=1500, to_cap=False):
    """An N-body scene (2..8 bodies) in nbody_fuzzer.cpp's layout, every value a raw double."""
    n = len(masses)
    per_pair = len(restitution) > 1
    assert len(restitution) in ((n if ring else n - 1) if per_pair else 1,)
    header = bytes([NBODY_EVENTS[events] | int(ring is not None) << 2 | NBODY_MODEL[model] << 3 | int(per_pair) << 5
                    | int(to_cap) << 6, n - 2, NBODY_CAP[cap]])
    values = [*masses, *positions, *velocities, *restitution]
    if ring is not None:
        values.append(ring)
    if model != "constant":
        values.append(parameter)
    return header + struct.pack(f"<{len(values)}d", *values)


NBODY_SEEDS = {
    # Issue 32: a 4-body inelastic ring that crashed (SIGSEGV) with events, and the 3-body ring
    # whose seam event published 2.42e198 m/s.
    "ring_crash_issue32_events_all": nbody((2.0, 0.75, 2.5, 2.75), (3.1875, 2.671875, 1.328125, 0.625),
                                           (0.75, -0.7109375, -0.98828125, -0.6796875), (0.40625,), ring=3.40625,
                                           to_cap=True),
    "ring_crash_issue32_events_none": nbody((2.0, 0.75, 2.5, 2.75), (3.1875, 2.671875, 1.328125, 0.625),
                                            (0.75, -0.7109375, -0.98828125, -0.6796875), (0.40625,), ring=3.40625,
                                            events="none", to_cap=True),
    # The same at 100 impacts: under ASan a run of 1500 takes 15-30 s, too slow to mutate.
    "ring_crash_issue32_events_all_100": nbody((2.0, 0.75, 2.5, 2.75), (3.1875, 2.671875, 1.328125, 0.625),
                                               (0.75, -0.7109375, -0.98828125, -0.6796875), (0.40625,),
                                               ring=3.40625, cap=100, to_cap=True),
    "ring_seam_issue32": nbody((1.75, 2.75, 3.0), (2.09375, 1.796875, 0.59375), (0.0234375, 0.21875, -0.2265625),
                               (0.875, 0.8125, 0.46875), ring=3.609375, cap=100, to_cap=True),
    "ring_elastic_first3": nbody((1, 2, 3, 4), (3.5, 2.5, 1.5, 0.5), (1, -1, 0.5, -0.5), ring=4.0, events="first3"),
    "ring_two_bodies": nbody((1, 3), (1.5, 0.5), (1, -1), (0.5,), ring=2.0),
    "ring_tc": nbody((1, 1, 1, 1, 1), (4.5, 3.5, 2.5, 1.5, 0.5), (1, -1, 1, -1, 0.5), (0.5,), ring=5.0, model="tc",
                     parameter=0.01, cap=100, to_cap=True),
    # 100 impacts: 1500 took 96 s here, too slow for a seed.
    "ring_viscoelastic": nbody((1, 2, 1, 2), (3.5, 2.5, 1.5, 0.5), (1, -1, 1, -1), ring=4.0, model="viscoelastic",
                               parameter=10.0, cap=100, to_cap=True),
    "box_inelastic": nbody((INF, 1, 2, 3, INF), (4, 3, 2, 1, 0), (0, 1, -1, 0.5, 0), (0.5,), cap=1500, to_cap=True),
    "box_threshold": nbody((INF, 1, 1, INF), (3, 2, 1, 0), (0, 1, -1, 0), (0.5,), model="threshold", parameter=0.1,
                           cap=1500, to_cap=True),
    "heavy_light_heavy_1e60": nbody((1e60, 1, 1e60), (2, 1, 0), (-1, 0, 0.5), (0.5,)),
    "three_elastic_out_of_range": nbody((1, 1, 1), (2, 1, 0), (-1, -5e-324, 0)),
    "three_elastic_grazing": nbody((3, 1, 0.5), (2, 1, 0), (-1, 0, 0)),
    "chain_after_2_900": nbody((1, 2, 3, 4), (1, 0, -1e210, -2e210), (-1e-61, 0, 1e-61, 2e-61)),
    "sticky_chain": nbody((1, 2, 3, 4, 5), (4, 3, 2, 1, 0), (1, 0.5, 0, -0.5, -1), (0.0,)),
    "two_bodies_any_ratio": nbody((1e-300, 1e300), (1, 0), (-1, 1), (0.5,)),
    "per_pair_restitution": nbody((1, 2, 3, 4), (3, 2, 1, 0), (-1, 0, 0, 1), (1.0, 0.5, 0.0)),
    "bad_ring_wall": nbody((INF, 1, 1), (2.5, 1.5, 0.5), (0, 1, -1), ring=3.0),
}


def write(folder_name, seeds):
    folder = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", folder_name)
    os.makedirs(folder, exist_ok=True)
    for name, data in seeds.items():
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
    print(f"{len(seeds)} seeds in {folder}")


def main():
    write("core", SEEDS)
    write("nbody", NBODY_SEEDS)


if __name__ == "__main__":
    main()
