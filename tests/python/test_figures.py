"""The committed figures show the current model (issue 50, "a test fails when they are older than
the model they show"): scripts/figures.py regenerates each and records the hash of the parameters
(names and start values in modelDescription/) of the FMUs it shows; a parameter added, removed or
given another default since then fails here, until `scripts/figures.py` is run again."""

import importlib.util
import json
import re

from conftest import ROOT

spec = importlib.util.spec_from_file_location("figures", ROOT / "scripts" / "figures.py")
figures = importlib.util.module_from_spec(spec)
spec.loader.exec_module(figures)

RECORD = json.loads(figures.RECORD.read_text())


def test_every_committed_figure_is_recorded():
    """Every PNG in docs/figures, and the notebook, has a record: the command that made it."""
    pngs = {str(p.relative_to(ROOT)) for p in figures.FIGURES.glob("*.png")}
    made = {f for files, _, _ in figures.SPECS for f in files}
    assert pngs | {figures.NOTEBOOK} == made, "a figure with no command in scripts/figures.py, or one missing"
    assert set(RECORD) == made, "regenerate: .venv/bin/python scripts/figures.py"


def test_every_figure_shows_the_models_parameters_of_today():
    stale = [f"{name} (models {', '.join(r['models'])})" for name, r in RECORD.items()
             if r["parameters_sha256"] != figures.parameters_hash(r["models"])]
    assert not stale, ("older than the parameters of the models they show, regenerate with "
                       f"`.venv/bin/python scripts/figures.py --only {' '.join(s.split()[0] for s in stale)}`: "
                       + "; ".join(stale))


def test_the_hash_moves_with_a_default():
    """The check can fail: one start value changed gives another hash (and the hash reads every
    parameter of the models: the counts of the modelDescriptions' causality="parameter")."""
    models = ["HydraulicBoom", "PressureFeedbackController"]
    xml = "".join((ROOT / "modelDescription" / f"{m}.xml").read_text() for m in models)
    assert sum(len(figures.parameters(m)) for m in models) == len(re.findall(r'causality="parameter"', xml))
    original = figures.parameters
    try:
        figures.parameters = lambda m: [(n, s + "0" if n == "boom.damping" else s) for n, s in original(m)]
        changed = figures.parameters_hash(models)
    finally:
        figures.parameters = original
    assert changed != figures.parameters_hash(models)


def test_every_figure_a_page_shows_exists():
    """Each figure linked from README.md and docs/*.md is a committed, recorded file."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    for page in pages:
        for link in re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", page.read_text()):
            path = (page.parent / link).resolve().relative_to(ROOT)
            assert str(path) in RECORD, f"{page.name} shows {link}, which scripts/figures.py does not make"
