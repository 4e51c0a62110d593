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


def test_the_notebooks_limit_cycle_frequencies_are_the_baselines():
    """Its text gives U's limit-cycle frequency for each boom: the regression baselines' f_dom
    (the dominant frequency of p3 over the last third of U), to the one decimal stated."""
    import json

    from boomsim.paths import BASELINE_DIR

    text = "".join("".join(c.source) for c in nbformat.read(NOTEBOOK, as_version=4).cells if c.cell_type == "markdown")
    f_dom = {boom: json.loads((BASELINE_DIR / f"U-{boom}.json").read_text())["metrics"]["f_dom"]
             for boom in ("rigid", "flexible")}
    assert f"limit cycle of about {f_dom['rigid']:.1f} Hz (the rigid boom here; {f_dom['flexible']:.1f} Hz with the flexible one)" in text
