"""The notebooks of docs/notebooks, executed top to bottom with nbclient (kernel python3): each
asserts its physics in a cell, so any failing assertion or error fails its test. Each runs from a
copy in a temporary folder (issue 47: notebooks run from any copy, their data loaded from the
package), so a path relative to the repository fails. The kernel inherits this process's
environment (the sourced workspace's PYTHONPATH); its figures go to a scratch folder
(COLLISION_LAB_FIGURES), not to docs."""
import glob
import os
import re
import shutil

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
    '04_collapse': ['collapse_three_body.png', 'collapse_four_body.png', 'collapse_gas.png'],
    '05_haff_ring': ['haff_ring.png'],
}


def test_the_five_notebooks_are_there():
    assert [os.path.splitext(os.path.basename(p))[0] for p in PATHS] == sorted(FIGURES)


@pytest.mark.parametrize('path', PATHS, ids=[os.path.basename(p) for p in PATHS])
def test_notebook_runs_and_its_assertions_hold(path, tmp_path, monkeypatch):
    figures = tmp_path / 'figures'
    monkeypatch.setenv('COLLISION_LAB_FIGURES', str(figures))
    monkeypatch.setenv('MPLBACKEND', 'Agg')
    copy = tmp_path / 'copy'  # the notebook alone, away from the repository
    copy.mkdir()
    shutil.copy(path, copy)
    notebook = nbformat.read(str(copy / os.path.basename(path)), as_version=4)
    assert notebook.metadata['kernelspec']['name'] == 'python3'
    client = NotebookClient(notebook, timeout=None, kernel_name='python3',
                            resources={'metadata': {'path': str(copy)}})
    try:
        client.execute()
    except CellExecutionError as error:
        pytest.fail('%s failed:\n%s' % (os.path.basename(path), error), pytrace=False)
    name = os.path.splitext(os.path.basename(path))[0]
    for figure in FIGURES[name]:
        saved = figures / figure
        assert saved.is_file() and saved.stat().st_size > 10_000, figure
        assert os.path.isfile(os.path.join(NOTEBOOKS, 'figures', figure)), 'docs lacks ' + figure


def test_no_notebook_reads_a_path_of_the_repository():
    """Data come from the package (collision_lab.preset, data_path), not from '../../config'."""
    for path in PATHS:
        code = '\n'.join(cell.source for cell in nbformat.read(path, as_version=4).cells if cell.cell_type == 'code')
        assert not re.search(r"'\.\.'|\.\./|config/", code), os.path.basename(path)


def words(name):
    notebook = nbformat.read(os.path.join(NOTEBOOKS, name + '.ipynb'), as_version=4)
    return ' '.join(' '.join(cell.source for cell in notebook.cells).split())


def test_collapse_notebook_says_what_it_shows_and_what_the_engine_cannot_decide():
    """Notebook 4 compares with McNamara and Young in their regime with an elastic control,
    names the undecided as a limit of the engine's proof, and takes up Dolmaire's four-body
    pattern above 0.0718 (issue 47); its cells assert the physics of each."""
    text = words('04_collapse')
    for phrase in ("McNamara and Young's regime", 'r = 0.8 to 0.95', 'elastic control', 'cannot yet decide',
                   'a limit of its proof, not physics', '5 - 2 sqrt 6', 'ababcb', 'not "no collapse"',
                   'rs = [0.8, 0.85, 0.9, 0.95, 1.0]', 'Ns = [4, 8, 12, 16, 24, 32, 48, 64, 96, 128]',
                   'assert abs(lo - (5 - 2 * math.sqrt(6))) < 1e-9', "assert s4['collapsed']"):
        assert phrase in text, phrase
    assert 'still colliding at the cap of 150' not in text  # the old proxy, which called elastic gases collapsing


def test_haff_notebook_fits_freely_shows_tau_and_the_window():
    """Notebook 5 fits the exponent freely beside Haff's 2, shows the kinetic-theory tau and
    the fit window, the measured T(0), and the run's length in units of tau; the whole-run fit
    is printed, not drawn."""
    text = words('05_haff_ring')
    for phrase in ("cl.preset('granular_ring')", 'plot.fit_haff_exponent', 'plot.haff_tau',
                   'window=window, free_exponent=True, tau_kinetic=tau', 'T(0) = %.4f J measured',
                   '= %.1f tau', 'Kinetic Theory of Granular Gases', 'not drawn'):
        assert phrase in text, phrase
