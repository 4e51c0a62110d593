"""Where the package finds what it runs: the scenario catalogue, baselines and sweep files (package
data), the .fmu files (packed into the wheel, or `boomsim pack`'s output in a checkout) and the
`boomsim` binary of a checkout (the native runner, the linear analysis)."""

from __future__ import annotations

import os
import pathlib

from .errors import UsageError

PACKAGE = pathlib.Path(__file__).resolve().parent
SCENARIO_DIR = PACKAGE / "scenarios"
BASELINE_DIR = PACKAGE / "baselines"
SWEEP_DIR = PACKAGE / "sweeps"
#: The .fmu files a wheel carries (scripts/wheel puts them there): <Id>.fmu (FMI 2.0), fmi3/<Id>.fmu.
WHEEL_FMU_DIR = PACKAGE / "fmus"

#: The repository when the package runs from a checkout (an editable install of python/), else None.
CHECKOUT = PACKAGE.parents[1] if (PACKAGE.parents[1] / "Cargo.toml").exists() else None
#: The `boomsim` binary of the checkout (`cargo build --release`); None outside one.
BOOMSIM = CHECKOUT / "target" / "release" / "boomsim" if CHECKOUT else None
#: Where the scripts write by default: the checkout's out/, else ./out.
OUT = CHECKOUT / "out" if CHECKOUT else pathlib.Path("out")

MODELS = ("HydraulicBoom", "PressureFeedbackController", "HydraulicCircuit", "BoomMechanics")
#: The FMI 3.0 FMUs: every model's, and the controller sampled by a Clock (FMI 3.0 Model Exchange only).
FMI3_MODELS = (*MODELS, "ClockedPressureFeedbackController")


def fmu_dir() -> pathlib.Path:
    """The folder of the FMI 2.0 .fmu files (FMI 3.0 in its fmi3/): $BOOMSIM_FMU_DIR when set, else
    the checkout's target/fmu (`boomsim pack`), else the wheel's."""
    if os.environ.get("BOOMSIM_FMU_DIR"):
        return pathlib.Path(os.environ["BOOMSIM_FMU_DIR"])
    return CHECKOUT / "target" / "fmu" if CHECKOUT else WHEEL_FMU_DIR


def fmu(model: str, fmi: int = 2) -> pathlib.Path:
    """The path of `model`'s .fmu (one of MODELS, or of FMI3_MODELS for FMI 3.0) for FMI `fmi` 2
    or 3; a UsageError names a missing file and how to make it."""
    if fmi not in (2, 3):
        raise UsageError(f"fmi={fmi!r}: 2 (FMI 2.0) or 3 (FMI 3.0)")
    if model not in (MODELS if fmi == 2 else FMI3_MODELS):
        known = ", ".join(MODELS) + (f" (FMI 3.0 also {FMI3_MODELS[-1]})" if fmi == 2 else f", {FMI3_MODELS[-1]}")
        raise UsageError(f"unknown model \"{model}\" in FMI {fmi}.0: one of {known}")
    path = fmu_dir() / ("fmi3" if fmi == 3 else "") / f"{model}.fmu"
    if not path.exists():
        fix = ("run `cargo build --release && target/release/boomsim pack`" if CHECKOUT
               else "install the wheel of `bash scripts/wheel`, which carries the FMUs")
        raise UsageError(f"{path} is missing: {fix}")
    return path


def boomsim_binary() -> pathlib.Path:
    """The checkout's `boomsim` binary; a UsageError where there is none."""
    if BOOMSIM is None:
        raise UsageError("the native runner and the linear analysis need the `boomsim` binary of a checkout "
                         "(cargo build --release): this installed package has none")
    if not BOOMSIM.exists():
        raise UsageError(f"{BOOMSIM} is missing: run `cargo build --release`")
    return BOOMSIM
