"""examples/thesis_figures.ipynb runs from top to bottom (nbclient, the venv's ipykernel) in a
temporary folder: a cell that raises fails the test with its traceback. Its figures are drawn
(three PNG outputs: the lowering of U and B, the filter map, the Bode plot). About 25 s."""

import pathlib

import nbclient
import nbformat

NOTEBOOK = pathlib.Path(__file__).resolve().parents[2] / "examples" / "thesis_figures.ipynb"


def test_the_thesis_figures_notebook_runs(tmp_path):
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbclient.NotebookClient(nb, timeout=600, resources={"metadata": {"path": str(tmp_path)}}).execute()
    images = [o for c in nb.cells for o in c.get("outputs", []) if "image/png" in o.get("data", {})]
    assert len(images) == 3
    assert (tmp_path / "out" / "filter-sweep" / "summary.md").exists() and (tmp_path / "out" / "bode.png").exists()
