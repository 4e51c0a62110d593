"""The console commands of the package (pyproject.toml's [project.scripts]): each runs a module's
`main` with the one-line errors of `errors.cli`; `python -m boomsim.<module>` runs the same."""

from __future__ import annotations

import importlib

from .errors import cli


def _command(module: str):
    def command() -> int:
        return cli(importlib.import_module(f"{__package__}.{module}").main)

    command.__doc__ = f"boomsim.{module}.main, its UsageError as one line and exit status 2"
    return command


cosim = _command("cosim")
regress = _command("regression")
sweep = _command("parameter_sweep")
split = _command("split")
ssp = _command("ssp")
rig_loop = _command("rig_loop")
clocked = _command("clocked")
instability = _command("instability")
linearize_scenario = _command("linearize_scenario")
plot_bode = _command("plot_bode")
mujoco = _command("mujoco")
mujoco_scene = _command("mujoco_scenes")
