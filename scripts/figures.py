"""Regenerates every committed figure (docs/figures/*.png) and the notebook's outputs
(examples/thesis_figures.ipynb), and records in docs/figures/figures.json, for each, the command
that made it and a hash of the parameters of the models it shows (their names and start values in
the committed modelDescription/*.xml). tests/python/test_figures.py fails when a model's
parameters no longer hash to what a figure recorded: the figure is older than the model.

    .venv/bin/python scripts/figures.py [--only NAME ...]     # about 2 minutes on 2 cores

Needs `cargo build --release` and `target/release/boomsim pack` (the FMUs), and MUJOCO_GL=osmesa
for MuJoCo's renders (set here when unset). What the hash does not see: a change of the equations
that moves no parameter's start value (regenerate by hand then, and say so in the commit)."""

import argparse
import hashlib
import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
RECORD = FIGURES / "figures.json"
NOTEBOOK = "examples/thesis_figures.ipynb"
PY = sys.executable

# Each figure: the files it writes, the command that writes them (run from the checkout; a
# function of this script's where the command is Python of its own) and the FMUs whose parameters
# it shows. The notebook runs U and B (HydraulicBoom + the controller), the filter sweep and the
# flexible arm's Bode plot.
SPECS = [
    (["docs/figures/u_against_b.png"], "u_against_b", ["HydraulicBoom", "PressureFeedbackController"]),
    (["docs/figures/linearize_bode.png"], [PY, "-m", "boomsim.plot_bode", "docs/figures/linearize_bode.png"],
     ["HydraulicBoom", "PressureFeedbackController"]),
    *((["docs/figures/mujoco_%s.png" % s, "docs/figures/mujoco_%s_render.png" % s],
       [PY, "-m", "boomsim.mujoco_scenes", s, "--out", "docs/figures/mujoco_%s.png" % s,
        "--render", "docs/figures/mujoco_%s_render.png" % s],
       ["HydraulicCircuit", "BoomMechanics"]) for s in ("touchdown", "knuckle")),
    ([NOTEBOOK], "notebook", ["HydraulicBoom", "PressureFeedbackController"]),
]


def parameters(model: str) -> list[tuple[str, str]]:
    """The parameters of `model` as (name, start), from its committed FMI 2.0 modelDescription."""
    root = ET.parse(ROOT / "modelDescription" / f"{model}.xml").getroot()
    return [(v.get("name"), v[0].get("start"))
            for v in root.iter("ScalarVariable") if v.get("causality") == "parameter"]


def parameters_hash(models: list[str]) -> str:
    """SHA-256 of the models' parameters, names and start values, in the files' order."""
    text = "\n".join(f"{m}|{name}={start}" for m in models for name, start in parameters(m))
    return hashlib.sha256(text.encode()).hexdigest()


def u_against_b() -> None:
    """The README's figure: U against B, rigid boom, the feedback from t = 0 (scripts/demo.py's)."""
    from boomsim import cosim
    from boomsim.plots import plot_u_against_b
    from boomsim.scenarios import load_scenario

    u, b = (cosim.run(load_scenario(s), "rigid", feedback_start=load_scenario(s)["starts"][0]) for s in ("U", "B"))
    plot_u_against_b(u, b, ROOT / "docs" / "figures" / "u_against_b.png")


def notebook() -> None:
    """Runs the notebook from top to bottom in a temporary folder (its files go to out/ there)
    and saves its outputs in place."""
    import tempfile

    import nbclient
    import nbformat

    nb = nbformat.read(ROOT / NOTEBOOK, as_version=4)
    with tempfile.TemporaryDirectory() as folder:
        nbclient.NotebookClient(nb, timeout=600, resources={"metadata": {"path": folder}}).execute()
    nbformat.write(nb, ROOT / NOTEBOOK)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="+", choices=[files[0] for files, _, _ in SPECS], help="regenerate these only")
    args = ap.parse_args(argv)
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "osmesa")}
    record = json.loads(RECORD.read_text()) if RECORD.exists() else {}
    specs = [spec for spec in SPECS if not args.only or spec[0][0] in args.only]
    for k, (files, command, models) in enumerate(specs, 1):
        print(f"[{k}/{len(specs)}] {', '.join(files)}", flush=True)
        if isinstance(command, str):
            globals()[command]()
            command = f"scripts/figures.py ({command})"
        else:
            subprocess.run(command, cwd=ROOT, env=env, check=True)
            command = " ".join(["python", *command[1:]])
        for f in files:
            record[f] = {"command": command, "models": models, "parameters_sha256": parameters_hash(models)}
    RECORD.write_text(json.dumps(dict(sorted(record.items())), indent=2) + "\n")
    print(f"figures: {len(specs)} commands run, recorded in {RECORD.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
