"""The co-simulation loop of one or more HydraulicCircuit instances (FMI 2.0 or 3.0 Co-Simulation
through fmpy), each with its valve command and optionally its PressureFeedbackController, and one
mechanics (boomsim.mechanics) with a cylinder for each: boomsim.split (BoomMechanics) and
boomsim.mujoco (MuJoCo) run it.

Couplings (docs/coupling.md):
    plain        Gauss-Seidel: mechanics first with F_k held -> x_k+1, v_k+1 -> each circuit steps
                 with v linear from v_k to v_k+1 -> F_k+1
    jacobi       plain, both step from the values at t_k (v held), as a parallel master does
    tlm          waves c_h, c_m exchanged once per step: mechanics first with c_h held, then each
                 circuit with c_m linear over the step
    tlm-jacobi   TLM, both from the waves at t_k

An input linear over a step is an input derivative in FMI 2.0 and an intermediate update in FMI
3.0 (boomsim.fmus.Direct.ramp): `slave` makes each instance with what its version needs.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .fmus import Direct, LinearInputs
from .result import COLUMNS, PLANT_OUT
from .scenarios import communication_references

COUPLINGS = ("plain", "jacobi", "tlm", "tlm-jacobi")
#: HydraulicCircuit's and BoomMechanics' port.coupling of each port.
PORT_CODES = {"plain": 0, "tlm": 1}
#: The input linear over each step: the circuit's of each port, the controller's.
RAMPED = {"tlm": "port.c_m", "plain": "cylinder.v", "controller": "p"}
#: Circuit outputs recorded (PLANT_OUT without the stroke and velocity, which come from
#: the mechanics).
CIRCUIT_OUT = [c for c in PLANT_OUT if not c.startswith("cylinder.")]
#: What the loop reads from a circuit after each step, in one call: CIRCUIT_OUT, the TLM wave
#: c_h, the force on the rod (the plain port's input to the mechanics) and the cylinder's friction.
READ = [*CIRCUIT_OUT, "port.c_h", "cylinder.F", "cylinder.F_fr"]
#: The columns of a recorded row: COLUMNS and the circuit's friction force (for energy balances).
RECORDED = [*COLUMNS, "cylinder.F_fr"]


class Unstable(Exception):
    """The coupled run diverged (a step was refused or the motion left the stroke)."""


def slave(fmu_file, name: str, ramped: str):
    """(instance, its LinearInputs or None): a Co-Simulation instance of `fmu_file` whose input
    `ramped` (a RAMPED value) the loop makes linear over each step; FMI 3.0 by intermediate update."""
    if fmu_file.fmi == 2:
        return fmu_file.slave(name), None
    inputs = LinearInputs([fmu_file.vr[ramped]])
    return fmu_file.slave(name, inputs=inputs), inputs


@dataclasses.dataclass
class Drive:
    """One cylinder's hydraulics, initialised: a HydraulicCircuit instance and its FmuFile, the
    operator's reference table ([t, u_ref] rows), and a PressureFeedbackController instance with
    its FmuFile, or None (the valve then takes the reference); each instance's LinearInputs
    (`slave`; FMI 3.0)."""

    circuit: object
    circuit_f: object
    table: np.ndarray
    controller: object = None
    controller_f: object = None
    circuit_inputs: LinearInputs | None = None
    controller_inputs: LinearInputs | None = None


def start_circuit(circuit_f, circuit, port: str, x: float, v: float, f_start: float, params: dict) -> None:
    """Sets a HydraulicCircuit in Initialization Mode to its mechanics' start (stroke, rate and the
    holding force; the port) and `params`, and leaves Initialization Mode."""
    for name, value in (("start.x", x), ("start.F", f_start), ("port.coupling", PORT_CODES[port]),
                        ("cylinder.x", x), ("cylinder.v", v), *params.items()):
        circuit_f.set(circuit, name, value)
    circuit.exitInitializationMode()


def start_controller(controller_f, controller, config: dict, p4: float, u_ref: float) -> None:
    """Sets a PressureFeedbackController in Initialization Mode to `config` (enable, and K_f,
    omega_f, u_min, u_max where given), its inputs to the circuit's p4 and the reference at t = 0,
    and leaves Initialization Mode."""
    for name in ("K_f", "omega_f", "u_min", "u_max"):
        if name in config:
            controller_f.set(controller, name, config[name])
    controller_f.set(controller, "enable", bool(config["enable"]))
    vc = controller_f.vr
    controller.setReal([vc["p"], vc["u_ref"]], [p4, u_ref])
    controller.exitInitializationMode()


class _Calls:
    """One drive's FMU calls of the loop, bound once (boomsim.fmus.Direct): per step one read
    (READ), one write of the inputs before the step, one of their
    ramp and the doStep."""

    def __init__(self, d: Drive, port: str):
        vh, c = d.circuit_f.vr, Direct(d.circuit)
        self.read = c.getter([vh[k] for k in READ])
        # TLM: the command and the mechanics' wave together; plain: the command, and after the
        # mechanics' step its stroke and rate
        self.inputs = c.setter([vh["valve.u_ref"]] + ([vh["port.c_m"]] if port == "tlm" else []))
        self.motion = c.setter([vh["cylinder.x"], vh["cylinder.v"]])
        self.ramp = c.ramp([vh[RAMPED[port]]], d.circuit_inputs)
        self.step = c.stepper()
        self.controlled = d.controller is not None
        if self.controlled:
            vc, k = d.controller_f.vr, Direct(d.controller)
            self.command = k.getter([vc["u"], vc["u_comp"]])
            self.p_ramp = k.ramp([vc[RAMPED["controller"]]], d.controller_inputs)
            self.control_inputs = k.setter([vc["p"], vc["u_ref"]])
            self.control_step = k.stepper()


def loop(drives: list[Drive], mechanics, coupling: str, step: float, n: int, record_every: int,
         control_every: int = 1) -> list[np.ndarray]:
    """`n` communication steps of `step` from t = 0 with the drives and mechanics initialised (each
    circuit's start state from the mechanics' start); per drive its recorded rows every
    `record_every` steps (RECORDED). The controllers step every `control_every` steps (their command held,
    p4 linear over their step). Raises Unstable when a stroke leaves its range or an output its
    domain."""
    tlm, gauss_seidel = coupling.startswith("tlm"), coupling in ("plain", "tlm")
    calls = [_Calls(d, "tlm" if tlm else "plain") for d in drives]
    x, v = mechanics.motion()
    # a recorded row takes its columns from a read and the mechanics' motion
    read = [*READ, "cylinder.x", "cylinder.v"]
    i_p4, i_c_h, i_force = (read.index(c) for c in ("p4", "port.c_h", "cylinder.F"))
    order = [read.index(c) for c in RECORDED[4:]]
    y = [c.read()[:] for c in calls]
    stroke = [d.circuit.getReal([d.circuit_f.vr["cylinder.stroke"]])[0] for d in drives]
    refs = [communication_references(d.table, step, n) for d in drives]
    rows = [[] for _ in drives]
    held = [(0.0, 0.0)] * len(drives)  # each controller's (u, u_comp) over its step
    p4_held = [yi[i_p4] for yi in y]  # p4 at the start of each controller's step
    for k in range(n + 1):
        t = k * step
        for i, c in enumerate(calls):
            if not c.controlled:
                held[i] = (refs[i][k], 0.0)
            elif k % control_every == 0:
                held[i] = tuple(c.command())
            if k % record_every == 0:
                u, u_comp = held[i]
                values = y[i] + [x[i], v[i]]
                rows[i].append([t, refs[i][k], u_comp, u, *[values[j] for j in order]])
        if k == n:
            break
        for i in range(len(drives)):
            # a sum of finite outputs is finite: one test for all of them
            if not (-0.05 < x[i] < stroke[i] + 0.05) or not math.isfinite(sum(y[i])):
                raise Unstable(f"{coupling}, h = {step:g} s: the motion diverged at t = {t:.4g} s "
                               f"(cylinder {i}: x = {x[i]:.4g} m)")
        if tlm:
            c_m = mechanics.wave()
            for c, u, w in zip(calls, held, c_m):
                c.inputs((u[0], w))
            c_h = [yi[i_c_h] for yi in y]
            if gauss_seidel:
                mechanics.step(t, step, c_h)
                for c, c0, c1 in zip(calls, c_m, mechanics.wave()):
                    c.ramp(t, step, (c0,), (c1,))
                    c.step(t, step)
            else:
                for c in calls:
                    c.step(t, step)
                mechanics.step(t, step, c_h)
            x, v = mechanics.motion()
        else:
            for c, u in zip(calls, held):
                c.inputs((u[0],))
            if not gauss_seidel:
                for c in calls:
                    c.step(t, step)
            mechanics.step(t, step, [yi[i_force] for yi in y])
            x1, v1 = mechanics.motion()
            if gauss_seidel:
                for c, a, b in zip(calls, v, v1):
                    c.ramp(t, step, (a,), (b,))
                    c.step(t, step)
            x, v = x1, v1
            for c, xi, vi in zip(calls, x, v):
                c.motion((xi, vi))
        for i, c in enumerate(calls):
            y[i] = c.read()[:]
            if c.controlled and (k + 1) % control_every == 0:
                p4_next, macro, t0 = y[i][i_p4], control_every * step, (k + 1 - control_every) * step
                c.p_ramp(t0, macro, (p4_held[i],), (p4_next,))
                c.control_step(t0, macro)
                c.control_inputs((p4_next, refs[i][k + 1]))
                p4_held[i] = p4_next
    return [np.array(r) for r in rows]
