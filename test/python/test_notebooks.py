"""The notebooks of docs/notebooks, executed top to bottom with nbclient (kernel python3): each
asserts its physics in a cell, so any failing assertion or error fails its test. The kernel
inherits this process's environment (the sourced workspace's PYTHONPATH); its figures go to a
scratch folder (COLLISION_LAB_FIGURES), not to docs."""
import glob
import os

import nbformat
import pytest
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

NOTEBOOKS = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'docs', 'notebooks')
PATHS = sorted(glob.glob(os.path.join(NOTEBOOKS, '*.ipynb')))
# The figures each notebook saves (docs/notebooks/figures holds the ones looked at).
FIGURES = {
    '01_pi_billiard': ['pi_count.png', 'pi_wedge.png', 'pi_views.png'],
    '02_paper_formulas': ['paper_velocities.png', 'paper_energy_transfer.png', 'paper_count.png'],
    '03_mass_plane': ['mass_plane.png'],
    '04_collapse': ['collapse_three_body.png', 'collapse_gas.png'],
    '05_haff_ring': ['haff_ring.png'],
}


def test_the_five_notebooks_are_there():
    assert [os.path.splitext(os.path.basename(p))[0] for p in PATHS] == sorted(FIGURES)


@pytest.mark.parametrize('path', PATHS, ids=[os.path.basename(p) for p in PATHS])
def test_notebook_runs_and_its_assertions_hold(path, tmp_path, monkeypatch):
    monkeypatch.setenv('COLLISION_LAB_FIGURES', str(tmp_path))
    monkeypatch.setenv('MPLBACKEND', 'Agg')
    notebook = nbformat.read(path, as_version=4)
    assert notebook.metadata['kernelspec']['name'] == 'python3'
    client = NotebookClient(notebook, timeout=None, kernel_name='python3',
                            resources={'metadata': {'path': os.path.dirname(path)}})
    try:
        client.execute()
    except CellExecutionError as error:
        pytest.fail('%s failed:\n%s' % (os.path.basename(path), error), pytrace=False)
    name = os.path.splitext(os.path.basename(path))[0]
    for figure in FIGURES[name]:
        saved = tmp_path / figure
        assert saved.is_file() and saved.stat().st_size > 10_000, figure
        assert os.path.isfile(os.path.join(NOTEBOOKS, 'figures', figure)), 'docs lacks ' + figure
