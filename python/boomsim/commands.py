"""The console commands of the package (pyproject.toml's [project.scripts]): each runs a module's
`main` with the one-line errors of `errors.cli`; `python -m boomsim.<module>` runs the same."""

from __future__ import annotations

import importlib
import sys

from .errors import cli


#: The packages of the optional extras (pyproject.toml), by the module a command misses.
EXTRAS = {"mujoco": "mujoco", "dask": "sweeps", "distributed": "sweeps", "pyarrow": "sweeps", "pandas": "pandas",
          "libcosimpy": "ssp", "ecospy": "ssp"}


def _command(module: str):
    def command() -> int:
        try:
            return cli(lambda: importlib.import_module(f"{__package__}.{module}").main())
        except ModuleNotFoundError as e:
            top = (e.name or "").split(".")[0]
            if top not in EXTRAS:
                raise
            print(f"boomsim.{module} needs {top}: pip install \"boomsim[{EXTRAS[top]}]\"", file=sys.stderr)
            return 2

    command.__doc__ = (f"boomsim.{module}.main, its UsageError as one line and exit status 2, as is a missing "
                       "optional dependency (the extra to install)")
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
