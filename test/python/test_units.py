"""Units in DataFrame attributes (issue 47): every DataFrame the module returns carries
df.attrs['units'], column -> unit, for each column that has a unit; the column names stay."""
import pandas as pd
import pytest

import collision_lab
from collision_lab import plot

INF = float('inf')


def test_a_runs_events_table_names_its_units():
    run = collision_lab.run([100, 1, INF], [2, 1, 0], [-1, 0, 0])
    table = run.to_pandas()
    assert table.attrs['units'] == {'time': 's', 'position': 'm', 'energy_lost': 'J', 'total_energy': 'J',
                                    'total_momentum': 'kg m/s', 'v_A': 'm/s', 'v_B': 'm/s', 'v_C': 'm/s',
                                    'x_A': 'm', 'x_B': 'm', 'x_C': 'm'}
    # The columns keep their names; the dimensionless ones have no unit.
    assert list(table.columns[:4]) == ['kind', 'pair', 'index', 'pair_index']
    assert {'restitution', 'first_moved', 'cluster_impact'} <= set(table.columns) - set(table.attrs['units'])
    # A copy or a slice keeps them (pandas carries attrs).
    assert table[table['pair'] == 'AB'].attrs['units']['time'] == 's'


def test_many_bodies_name_every_bodys_columns():
    n = 30
    table = collision_lab.run([1.0] * n, list(range(n, 0, -1)), [0.0] * (n - 1) + [-1.0]).to_pandas()
    assert table.attrs['units']['v_#29'] == 'm/s' and table.attrs['units']['x_#26'] == 'm'
    assert sum(1 for c in table.columns if c.startswith(('v_', 'x_'))) == 2 * n
    assert all(c in table.columns for c in table.attrs['units'])


def test_a_sweeps_table_names_its_units():
    table = collision_lab.sweep(grid={'e': [1.0, 0.05]},
                                base=lambda p: dict(masses=[1, 1, 1], positions=[2, 1, 0], velocities=[-1, 0, 0],
                                                    restitution=p['e']))
    units = table.attrs['units']
    assert units == {'final_time': 's', 'energy_lost': 'J', 'compute_time_s': 's', 'collapse_time': 's',
                     'collapse_position': 'm', 'final_velocities': 'm/s', 'predicted_final_velocities': 'm/s',
                     'spiral_angle': 'rad', 'theta': 'rad', 'alpha': 'rad', 'omega': 'rad', 'psi': 'rad',
                     'paper_phi_bc': 'rad'}
    assert 'e' not in units and 'collision_count' not in units  # a parameter's unit is the caller's


def test_the_temperature_csv_table_names_its_units(tmp_path):
    path = tmp_path / 'T.csv'
    with pytest.warns(collision_lab.CapWarning):
        collision_lab.run([1, 2, 1.5, 1], [3, 2, 1, 0], [-1, 0.5, 0, 1], 0.9, ring=10, max_collisions=300,
                          events='none', temperature_csv=str(path))
    table, _ = plot.read_temperature_csv(str(path))
    assert isinstance(table, pd.DataFrame)
    assert list(table.columns) == ['impacts', 'time_s', 'temperature_J']
    assert table.attrs['units'] == {'time_s': 's', 'temperature_J': 'J'}
