"""boomsim.mujoco: HydraulicCircuit instances driving the cylinders of a MuJoCo model (the extra
`pip install boomsim[mujoco]`; docs/mujoco.md).

Each cylinder is two sites of the MJCF model, one on each body it joins: boomsim adds a spatial
tendon between them (its length is the pin-to-pin length, l_retracted + stroke x; its velocity the
rate v) and a `general` actuator on the tendon (the force along it, > 0 pushing the sites apart).
Each cylinder has its own HydraulicCircuit (FMI 2.0 or 3.0 Co-Simulation through fmpy), its valve command
and optionally its PressureFeedbackController; the loop is boomsim.coupled's (plain or TLM port,
Gauss-Seidel or Jacobi). The TLM port's impedance -Z_c v is the actuator's affine velocity bias,
so MuJoCo's implicit integrators (implicitfast, implicit) treat it implicitly; the wave c_m is
computed from MuJoCo's tendon velocity (boomsim.mechanics).

    from boomsim import mujoco as bm
    xml = bm.boom_mjcf()                                  # the thesis' rigid boom
    runs = bm.run(xml, [bm.thesis_cylinder(command=[[0, 0], [0.3, 0], [0.5, -0.3], [15, -0.3]])],
                  stop_time=15.0)
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from fmpy.fmi1 import FMICallException

from .coupled import COUPLINGS, RAMPED, RECORDED, Drive, Unstable, loop, slave, start_circuit, start_controller
from .errors import UsageError
from .fmus import FmuFile, release
from .mechanics import Mechanics
from .result import Result
from .scenarios import reference

try:
    import mujoco
except ModuleNotFoundError as e:  # pragma: no cover - the extra is missing
    raise ModuleNotFoundError("boomsim.mujoco needs MuJoCo: pip install boomsim[mujoco]", name="mujoco") from e

#: Stability bound of a damper c on an effective mass m under an explicit integrator, on
#: c dt / m: forward (semi-implicit) Euler's velocity update 1 - c dt / m stays within the unit
#: circle below 2, classical RK4's amplification 1 - z + z^2/2 - z^3/6 + z^4/24 below 2.785. The
#: implicit integrators have none.
EXPLICIT_DAMPING_BOUND = {mujoco.mjtIntegrator.mjINT_EULER: 2.0, mujoco.mjtIntegrator.mjINT_RK4: 2.785}


@dataclasses.dataclass
class Cylinder:
    """One hydraulic cylinder of an MJCF model.

    name           the cylinder's name (its tendon and actuator are `<name>` in the compiled model)
    site_from      the site of the barrel's pin
    site_to        the site of the rod's pin
    l_retracted    the sites' distance at stroke 0 [m] (HydraulicCircuit's cylinder.stroke bounds it)
    command        the valve command u_ref: a number, or [t, u_ref] rows, linear between them
    controller     PressureFeedbackController parameters ({"enable": True, "K_f": ..., ...}), or
                   None: the valve takes the command
    circuit        HydraulicCircuit parameters ({"port.Z_c": 3e5, "pcv.dp_set": ...})
    rod_mass       the rod and piston [kg] moving with the stroke, as the tendon's armature, with
                   their weight along the cylinder's axis; 0 when the model's bodies carry them
    """

    name: str
    site_from: str
    site_to: str
    l_retracted: float
    command: object = 0.0
    controller: dict | None = None
    circuit: dict = dataclasses.field(default_factory=dict)
    rod_mass: float = 0.0

    def table(self) -> np.ndarray:
        """The command as [t, u_ref] rows."""
        table = np.atleast_2d(np.asarray(self.command, dtype=float))
        if table.shape == (1, 1):
            table = np.array([[0.0, table[0, 0]]])
        if table.ndim != 2 or table.shape[1] != 2 or not np.all(np.diff(table[:, 0]) >= 0):
            raise UsageError(f"cylinder {self.name!r}: command must be a number or [t, u_ref] rows with "
                             f"rising t, not {self.command!r}")
        return table


#: Half the side of the payload's cube in `boom_mjcf` [m]: for drawing and contact; the thesis
#: does not size it.
PAYLOAD_HALF = 0.15

#: BoomMechanics' variables the MJCF of the thesis' boom is built from: the rigid boom's geometry
#: and mass (calculated parameters), the start angle and payload, the cylinder's and gravity.
GEOMETRY = ("boom.joint.x", "boom.joint.y", "boom.pin.x", "boom.pin.y", "boom.cm.x", "boom.cm.y", "boom.m_D",
            "boom.J_B", "boom.theta", "payload.x", "payload.y", "boom.l_arm", "boom.b7", "cylinder.l_retracted",
            "cylinder.m_rod", "cylinder.stroke", "env.g")


def boom_geometry(start_stroke: float = 0.48, params: dict | None = None) -> dict:
    """BoomMechanics' GEOMETRY values with `params` (BoomMechanics parameters by name) at rest at
    `start_stroke` [m]: the same numbers the FMUs compute with, none copied."""
    f = FmuFile.get("BoomMechanics")
    for name in params or {}:
        if name not in f.vars or f.vars[name].causality != "parameter":
            raise UsageError(f"BoomMechanics has no parameter {name!r}")
    s = f.slave("boomsim.mujoco.geometry")
    try:
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        for name, value in {"boom.flexible": False, "start.x": start_stroke, **(params or {})}.items():
            f.set(s, name, value)
        s.exitInitializationMode()
        return dict(zip(GEOMETRY, s.getReal([f.vr[n] for n in GEOMETRY])))
    finally:
        release(s)


def boom_mjcf(start_stroke: float = 0.48, params: dict | None = None, timestep: float = 1e-3,
              integrator: str = "RK4") -> str:
    """MJCF of the thesis' rigid boom (2.1.1-2.1.2) from `boom_geometry`: the lower cylinder pin A
    at the origin (site `cylinder.lower`), the boom a body on a hinge at the joint B (joint
    `boom.theta`, its angle theta2, > 0 up, in MuJoCo's x-z plane: thesis x -> x, y -> z) with arm
    and payload's mass m_D, mass centre e_cm and J_B about B, the upper pin C (site
    `cylinder.upper`), and the keyframe `start` at rest at `start_stroke`. Its geoms carry no mass
    and touch nothing: a capsule along the arm and a cube of PAYLOAD_HALF at the payload's mass
    centre."""
    g = boom_geometry(start_stroke, params)
    theta = g["boom.theta"]
    rot = np.array([[np.cos(theta), np.sin(theta)], [-np.sin(theta), np.cos(theta)]])
    payload = [float(p) for p in rot @ (np.array([g["payload.x"], g["payload.y"]]) - [g["boom.joint.x"], g["boom.joint.y"]])]
    cm = (g["boom.cm.x"], g["boom.cm.y"])
    i_cm = g["boom.J_B"] - g["boom.m_D"] * (cm[0] ** 2 + cm[1] ** 2)  # about the mass centre (parallel axis)
    arm0, arm1 = -g["boom.b7"], g["boom.l_arm"] - g["boom.b7"]
    return f"""<mujoco model="boomsim thesis boom">
  <compiler angle="radian" inertiafromgeom="false"/>
  <option timestep="{timestep!r}" integrator="{integrator}" gravity="0 0 {-g['env.g']!r}"/>
  <worldbody>
    <site name="cylinder.lower" pos="0 0 0" size="0.03"/>
    <geom name="lower_beam" type="capsule" fromto="0 0 0 {g['boom.joint.x']!r} 0 {g['boom.joint.y']!r}" size="0.04"
          contype="0" conaffinity="0"/>
    <body name="boom" pos="{g['boom.joint.x']!r} 0 {g['boom.joint.y']!r}">
      <joint name="boom.theta" type="hinge" axis="0 -1 0"/>
      <inertial pos="{cm[0]!r} 0 {cm[1]!r}" mass="{g['boom.m_D']!r}" diaginertia="{i_cm!r} {i_cm!r} {i_cm!r}"/>
      <geom name="arm" type="capsule" fromto="{arm0!r} 0 0 {arm1!r} 0 0" size="0.05" contype="0" conaffinity="0"/>
      <geom name="payload" type="box" pos="{payload[0]!r} 0 {payload[1]!r}" size="{PAYLOAD_HALF} {PAYLOAD_HALF} {PAYLOAD_HALF}"
            contype="0" conaffinity="0"/>
      <site name="cylinder.upper" pos="{g['boom.pin.x']!r} 0 {g['boom.pin.y']!r}" size="0.03"/>
    </body>
  </worldbody>
  <keyframe>
    <key name="start" qpos="{theta!r}"/>
  </keyframe>
</mujoco>
"""


def thesis_cylinder(command=0.0, controller: dict | None = None, circuit: dict | None = None,
                    params: dict | None = None) -> Cylinder:
    """The thesis' cylinder between `boom_mjcf`'s sites: its retracted length and rod mass from
    BoomMechanics (with `params`), the command, controller and circuit parameters as given."""
    g = boom_geometry(params=params)
    return Cylinder("boom", "cylinder.lower", "cylinder.upper", g["cylinder.l_retracted"], command, controller,
                    dict(circuit or {}), g["cylinder.m_rod"])


#: The circuit's work counts a run reports (its solver.* locals).
COUNTS = ("steps", "rhs_evals", "jacobian_evals")


class _Rod(NamedTuple):
    """One cylinder in the compiled model: its rod's weight factor m_rod g_z [N] and ids."""

    weight: float
    site_from: int
    site_to: int
    tendon: int
    actuator: int
    l_retracted: float


class MujocoMechanics(Mechanics):
    """The cylinders of an MjSpec (`add_cylinders`) compiled, stepped `substeps` timesteps per
    communication step, at rest in the keyframe `key` at the start (qpos0 without one).
    `monitor(t, model, data)`: called at t = 0 and after every `record_every`-th step, its
    returned numbers kept in `records`."""

    def __init__(self, spec, cylinders: list[Cylinder], port: str, z_c, alpha, substeps: int = 1,
                 key: str | None = "start", monitor=None, record_every: int = 1):
        super().__init__(port, z_c, alpha)
        add_cylinders(spec, cylinders, port)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        if key is not None:
            k = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_KEY, key)
            if k < 0:
                raise UsageError(f"the MJCF model has no keyframe {key!r} for the start (key=None: qpos0)")
            mujoco.mj_resetDataKeyframe(self.model, self.data, k)
        ids = lambda kind, names: np.array([mujoco.mj_name2id(self.model, kind, n) for n in names])  # noqa: E731
        self.tendon = ids(mujoco.mjtObj.mjOBJ_TENDON, [c.name for c in cylinders])
        self.actuator = ids(mujoco.mjtObj.mjOBJ_ACTUATOR, [c.name for c in cylinders])
        self.site_from = ids(mujoco.mjtObj.mjOBJ_SITE, [c.site_from for c in cylinders])
        self.site_to = ids(mujoco.mjtObj.mjOBJ_SITE, [c.site_to for c in cylinders])
        self.model.actuator_biasprm[self.actuator, 2] = -np.array(self.z_c) if port == "tlm" else 0.0
        #: Each cylinder's ids and numbers for the per-step work, in Python numbers (numpy's per-call
        #: cost is most of a step's).
        self._rods = [_Rod(float(c.rod_mass * self.model.opt.gravity[2]), int(a), int(b), int(t), int(u), c.l_retracted)
                      for c, a, b, t, u in zip(cylinders, self.site_from, self.site_to, self.tendon, self.actuator)]
        self.substeps = substeps
        self.monitor, self.record_every, self.records, self.qpos, self.steps = monitor, record_every, [], [], 0
        mujoco.mj_forward(self.model, self.data)
        self._read_motion()
        self._holding = self._static_force()
        self._record(0.0)

    def _record(self, t: float) -> None:
        if self.steps % self.record_every == 0:
            self.qpos.append(self.data.qpos.copy())
            if self.monitor is not None:
                self.records.append([float(y) for y in self.monitor(t, self.model, self.data)])

    def _jacobian(self) -> np.ndarray:
        """The cylinders' tendon Jacobians (rows) now."""
        m = self.model
        dense = np.zeros((m.ntendon, m.nv))
        mujoco.mju_sparse2dense(dense, self.data.ten_J, m.ten_J_rownnz, m.ten_J_rowadr, m.ten_J_colind)
        return dense[self.tendon]

    def _rod_weight(self) -> list[float]:
        """The rod's weight along each cylinder's axis, > 0 pushing out: m_rod g . e, e the unit
        axis from the barrel's pin to the rod's (rigid boom: -m_rod g sin theta1, eq. 2.62)."""
        xpos, length = self.data.site_xpos, self.data.ten_length
        return [r.weight * (xpos[r.site_to, 2] - xpos[r.site_from, 2]) / length[r.tendon] for r in self._rods]

    def effective_mass(self) -> np.ndarray:
        """Each cylinder's effective mass at its pins now, 1 / (J M^-1 J^T) (MuJoCo's M holds the
        tendon's armature): the mass that a force along that cylinder alone accelerates [kg]."""
        m, d = self.model, self.data
        out = []
        for row in self._jacobian():
            minv_j = np.zeros((1, m.nv))
            mujoco.mj_solveM(m, d, minv_j, row.reshape(1, -1))
            out.append(1.0 / float(row @ minv_j[0]))
        return np.array(out)

    def holding_force(self) -> np.ndarray:
        return self._holding

    def _static_force(self) -> np.ndarray:
        """The forces along the cylinders that hold the model at rest at the start: least squares
        of J^T F = qfrc_bias - qfrc_passive - qfrc_constraint over the joints, and the rods' weight.
        The constraint forces (a rope, a contact) depend on F: the fixed point of F and their
        solution, to 1e-10 of F."""
        m, d = self.model, self.data
        force = np.zeros(len(self.tendon))
        for _ in range(100):
            d.ctrl[self.actuator] = force + np.array(self._rod_weight())
            mujoco.mj_forward(m, d)
            load = d.qfrc_bias - d.qfrc_passive - d.qfrc_constraint
            new = np.linalg.lstsq(self._jacobian().T, load, rcond=None)[0]
            done = np.all(np.abs(new - force) <= 1e-10 * np.abs(new))
            force = new
            if done:
                break
        d.ctrl[:] = 0.0
        mujoco.mj_forward(m, d)
        return force - np.array(self._rod_weight())

    def motion(self) -> tuple[list[float], list[float]]:
        return self._motion

    def _read_motion(self) -> None:
        """Reads the strokes and rates once after each step (`motion` is asked twice a step)."""
        length, rate = self.data.ten_length, self.data.ten_velocity
        self._motion = ([float(length[r.tendon]) - r.l_retracted for r in self._rods],
                        [float(rate[r.tendon]) for r in self._rods])

    def advance(self, t: float, h: float, u) -> None:
        """`substeps` mj_step with the port input u plus the rods' weight as the actuators'
        controls (the weight's direction from the step's start), then mj_forward: after mj_step
        the tendons' lengths and velocities are still those of the step's start."""
        m, d = self.model, self.data
        ctrl = d.ctrl
        for _ in range(self.substeps):
            for r, ui, w in zip(self._rods, u, self._rod_weight()):
                ctrl[r.actuator] = ui + w
            mujoco.mj_step(m, d)
        mujoco.mj_forward(m, d)
        self._read_motion()
        self.steps += 1
        self._record(t + h)


def add_cylinders(spec, cylinders: list[Cylinder], port: str) -> None:
    """Adds each cylinder's spatial tendon (site_from to site_to; the rod mass as its armature) and
    `general` actuator (gain 1, affine bias: TLM's -Z_c v) to the MjSpec `spec`."""
    names = [c.name for c in cylinders]
    for c in cylinders:
        if names.count(c.name) > 1:
            raise UsageError(f"cylinder {c.name!r}: two cylinders have that name")
        if spec.tendon(c.name) is not None or spec.actuator(c.name) is not None:
            raise UsageError(f"cylinder {c.name!r}: the MJCF model already has a tendon or actuator of that name")
        for site in (c.site_from, c.site_to):
            if spec.site(site) is None:
                known = ", ".join(sorted(s.name for s in spec.sites if s.name)) or "none"
                raise UsageError(f"cylinder {c.name!r}: the MJCF model has no site {site!r} (its sites: {known})")
        if not (c.rod_mass >= 0.0 and c.l_retracted > 0.0):
            raise UsageError(f"cylinder {c.name!r}: l_retracted = {c.l_retracted} m must be > 0 and "
                             f"rod_mass = {c.rod_mass} kg >= 0")
        t = spec.add_tendon(name=c.name, armature=c.rod_mass)
        t.wrap_site(c.site_from)
        t.wrap_site(c.site_to)
        a = spec.add_actuator(name=c.name, target=c.name, trntype=mujoco.mjtTrn.mjTRN_TENDON)
        a.biastype = mujoco.mjtBias.mjBIAS_AFFINE if port == "tlm" else mujoco.mjtBias.mjBIAS_NONE


def mjcf_spec(model) -> "mujoco.MjSpec":
    """An MjSpec of `model`: MJCF text, a path to an .xml file, or an MjSpec (copied)."""
    if isinstance(model, mujoco.MjSpec):
        return model.copy()
    text = str(model)
    try:
        if text.lstrip().startswith("<"):
            return mujoco.MjSpec.from_string(text)
        return mujoco.MjSpec.from_file(text)
    except Exception as e:  # noqa: BLE001 - MuJoCo's parse errors are ValueError or its own
        raise UsageError(f"the MJCF model does not load: {e}") from e


def check_start(mech: MujocoMechanics, cylinders: list[Cylinder], strokes) -> None:
    """Every cylinder's start stroke within [0, stroke] (HydraulicCircuit's cylinder.stroke)."""
    x, _ = mech.motion()
    for c, xi, stroke in zip(cylinders, x, strokes):
        if not 0.0 <= xi <= stroke:
            l = xi + c.l_retracted
            raise UsageError(f"cylinder {c.name!r}: its sites {c.site_from!r} and {c.site_to!r} are {l:.6g} m apart at "
                             f"the start, a stroke of {xi:.6g} m (l_retracted = {c.l_retracted:g} m) outside the "
                             f"cylinder's [0, {stroke:g}] m")


def check_damping_bound(mech: MujocoMechanics, cylinders: list[Cylinder]) -> None:
    """The TLM port's damper -Z_c v under an explicit integrator (Euler, RK4): Z_c dt / m_eff
    within EXPLICIT_DAMPING_BOUND (docs/mujoco.md); the implicit integrators have no bound."""
    integrator = mujoco.mjtIntegrator(mech.model.opt.integrator)
    bound = EXPLICIT_DAMPING_BOUND.get(integrator)
    if bound is None:
        return
    dt = mech.model.opt.timestep
    for c, z_c, m_eff in zip(cylinders, mech.z_c, mech.effective_mass()):
        if z_c * dt / m_eff >= bound:
            raise UsageError(
                f"cylinder {c.name!r}: timestep {dt:g} s with the TLM port's Z_c = {z_c:g} N s/m on an effective mass of "
                f"{m_eff:.4g} kg gives Z_c dt / m = {z_c * dt / m_eff:.3g}, beyond {integrator.name}'s stability bound "
                f"{bound:g}: use integrator=\"implicitfast\" (the damper implicit) or a timestep below "
                f"{bound * m_eff / z_c:.3g} s")


def whole_multiple(name: str, value: float, of: str, unit: float) -> int:
    """`value` / `unit`, a whole number >= 1, or a UsageError naming `name`."""
    k = int(round(value / unit))
    if k < 1 or abs(k * unit - value) > 1e-9 * value:
        raise UsageError(f"{name} = {value:g} s must be {of} {unit:g} s or a whole multiple of it")
    return k


@dataclasses.dataclass
class MujocoRun:
    """A coupled run: a Result per cylinder (by name; RECORDED's columns), the monitor's rows and
    MuJoCo's qpos (one per recorded communication point), the compiled MjModel with the cylinders'
    tendons and actuators, and the cylinders."""

    results: dict
    monitored: np.ndarray
    qpos: np.ndarray
    model: object
    cylinders: list


def run(model, cylinders: list[Cylinder], coupling: str = "tlm", step: float | None = None,
        stop_time: float = 1.0, key: str | None = "start", monitor=None, record_every: int | None = None,
        control_step: float | None = None, fmi: int = 2) -> MujocoRun:
    """Couples a HydraulicCircuit to each cylinder of the MJCF `model` (text, path or MjSpec), from
    rest at the keyframe `key`, for `stop_time` [s] at the communication step `step` (MuJoCo's
    timestep when None, else a whole multiple of it) with `coupling` (boomsim.coupled.COUPLINGS).
    Records every `record_every` steps (1 ms by default); `monitor(t, model, data)` returns the
    numbers to keep at each recorded point (a contact force, a body position). The controllers
    step every `control_step` (default: `step`; a whole multiple of it). `fmi`: the FMUs' FMI
    version, 2 or 3 (Co-Simulation; FMI 3.0 ramps its inputs by intermediate update)."""
    if coupling not in COUPLINGS:
        raise UsageError(f"coupling = {coupling!r}: must be one of {COUPLINGS}")
    if not cylinders:
        raise UsageError("no cylinders: give at least one boomsim.mujoco.Cylinder")
    if fmi not in (2, 3):
        raise UsageError(f"fmi = {fmi!r}: the FMUs are FMI 2 or 3")
    spec = mjcf_spec(model)
    tables = [c.table() for c in cylinders]
    port = "tlm" if coupling.startswith("tlm") else "plain"
    timestep = spec.option.timestep
    step = timestep if step is None else step
    substeps = whole_multiple("step", step, "MuJoCo's timestep", timestep)
    n = int(round(stop_time / step))
    record_every = record_every or max(1, int(round(1e-3 / step)))
    control_every = whole_multiple("control_step", step if control_step is None else control_step, "the step", step)
    circ_f, ctrl_f = FmuFile.get("HydraulicCircuit", fmi), FmuFile.get("PressureFeedbackController", fmi)
    for c in cylinders:
        for name in c.circuit:
            if name not in circ_f.vars or circ_f.vars[name].causality != "parameter":
                raise UsageError(f"cylinder {c.name!r}: HydraulicCircuit has no parameter {name!r}")
    # The model is built and checked before any FMU is instantiated: bad input leaves nothing behind.
    circuit = [{k: c.circuit.get(k, float(circ_f.vars[k].start)) for k in ("port.Z_c", "port.alpha", "cylinder.stroke")}
               for c in cylinders]
    mech = MujocoMechanics(spec, cylinders, port, [p["port.Z_c"] for p in circuit], [p["port.alpha"] for p in circuit],
                           substeps, key, monitor, record_every)
    check_start(mech, cylinders, [p["cylinder.stroke"] for p in circuit])
    if port == "tlm":
        check_damping_bound(mech, cylinders)
    (x, v), force = mech.motion(), mech.holding_force()
    instances = []
    try:
        drives = []
        for i, (c, table) in enumerate(zip(cylinders, tables)):
            circ, circ_inputs = slave(circ_f, f"{c.name}.circuit", RAMPED[port])
            instances.append(circ)
            circ.setupExperiment(startTime=0.0, stopTime=stop_time)
            circ.enterInitializationMode()
            start_circuit(circ_f, circ, port, x[i], v[i], force[i], c.circuit)
            ctrl = ctrl_inputs = None
            if c.controller is not None:
                ctrl, ctrl_inputs = slave(ctrl_f, f"{c.name}.controller", RAMPED["controller"])
                instances.append(ctrl)
                ctrl.setupExperiment(startTime=0.0, stopTime=stop_time)
                ctrl.enterInitializationMode()
                p4 = circ.getReal([circ_f.vr["p4"]])[0]
                start_controller(ctrl_f, ctrl, {"enable": True, **c.controller}, p4, reference(table, 0.0))
            drives.append(Drive(circ, circ_f, table, ctrl, ctrl_f, circ_inputs, ctrl_inputs))
        data = loop(drives, mech, coupling, step, n, record_every, control_every)
        counts = [dict(zip(COUNTS, map(int, d.circuit.getReal([circ_f.vr[f"solver.{k}"] for k in COUNTS]))))
                  for d in drives]
    except FMICallException as e:
        raise Unstable(f"{coupling}, h = {step:g} s: an FMU refused a call ({e}), the run diverged") from e
    finally:
        release(*instances)
    results = {}
    for c, table, rows, work in zip(cylinders, tables, data, counts):
        scenario = {"id": c.name, "stop_time": stop_time, "step": step, "reference": table}
        results[c.name] = Result(scenario, "mujoco", step, True, {col: rows[:, j] for j, col in enumerate(RECORDED)}, None,
                                 counts=work)
    return MujocoRun(results, np.array(mech.records), np.array(mech.qpos), mech.model, list(cylinders))


def scenario_run(sc: dict, coupling: str = "tlm", step: float = 5e-4, integrator: str = "RK4",
                 stop_time: float | None = None, fmi: int = 2) -> Result:
    """A boomsim scenario (its start stroke, reference, controller and [plant] parameters) with the
    thesis' rigid boom in MuJoCo at the communication step `step` (MuJoCo's timestep: `step`, at
    most 1 ms), the controller at the scenario's step (as HydraulicBoom's runs take it) or `step`."""
    boom = FmuFile.get("BoomMechanics").vars
    params = {k: v for k, v in sc["plant"].items() if k in boom and boom[k].causality == "parameter"}
    xml = boom_mjcf(sc["start_stroke"], params, timestep=min(step, 1e-3), integrator=integrator)
    circuit = {k: v for k, v in sc["plant"].items() if k in FmuFile.get("HydraulicCircuit").vars}
    controller = sc["controller"] if sc["controller"].get("enable") else None
    r = run(xml, [thesis_cylinder(sc["reference"], controller, circuit, params)], coupling, step,
            sc["stop_time"] if stop_time is None else stop_time, control_step=max(step, sc["step"]), fmi=fmi)
    return dataclasses.replace(r.results["boom"], scenario=sc)


#: Communication steps of `--table` [s].
TABLE_STEPS = (1e-3, 5e-4, 2.5e-4)


def main(argv=None):
    import argparse
    import time

    from . import cosim, split
    from . import metrics as mx
    from .scenarios import load_scenario

    ap = argparse.ArgumentParser(description="HydraulicCircuit driving the thesis' rigid boom in MuJoCo: "
                                 "a scenario against HydraulicBoom, the error table, the stability sweep")
    ap.add_argument("scenario", nargs="*", default=["U"])
    ap.add_argument("--coupling", default="tlm", choices=COUPLINGS)
    ap.add_argument("--step", type=float, default=5e-4)
    ap.add_argument("--integrator", default="RK4", choices=("Euler", "RK4", "implicit", "implicitfast"))
    ap.add_argument("--table", action="store_true", help="each metric's error against the step, plain and TLM")
    ap.add_argument("--sweep", action="store_true", help="largest stable step of each coupling (LIFT)")
    ap.add_argument("--alpha", type=float, default=0.0, help="TLM wave damping port.alpha of the sweep")
    ap.add_argument("--repeats", type=int, default=1, help="wall times: the best of this many runs")
    ap.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="the circuits' and controllers' FMI version")
    args = ap.parse_args(argv)
    if args.sweep:
        runner = lambda sc, c, h: scenario_run(sc, c, h, args.integrator, fmi=args.fmi)  # noqa: E731
        split.print_sweep(f"mujoco {args.integrator} alpha {args.alpha:g}",
                          split.sweep("rigid", alpha=args.alpha, runner=runner))
        return
    def timed(f):
        """f() and its best wall time of --repeats runs."""
        best = float("inf")
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            out = f()
            best = min(best, time.perf_counter() - t0)
        return out, best

    for sid in args.scenario:
        sc = load_scenario(sid)
        mono, t_mono = timed(lambda: cosim.run(sc, "rigid", 1e-3))
        ref = mx.compute(mono)
        cases = [(c, h) for c in ("tlm", "plain") for h in TABLE_STEPS] if args.table else [(args.coupling, args.step)]
        got = {}
        for c, h in cases:
            r, wall = timed(lambda: scenario_run(sc, c, h, args.integrator, fmi=args.fmi))
            got[c, h] = (mx.compute(r), wall, r.counts)
        print(f"\n{sid}-rigid, MuJoCo {args.integrator}: error of each metric against HydraulicBoom + controller "
              f"through fmpy at 1 ms (wall {t_mono:.2f} s, best of {args.repeats}; {mono.counts['rhs']} RHS); the "
              f"controller at 1 ms\n")
        print("| metric | HydraulicBoom | " + " | ".join(f"{c} {h * 1e3:g} ms" for c, h in cases) + " |")
        print("|---|---|" + "---|" * len(cases))
        for k, a in ref.items():
            if a is None or a == 0 or any(g[0][k] is None for g in got.values()):
                continue
            print(f"| {k} | {a:.5g} | " + " | ".join(f"{(g[0][k] - a) / abs(a) * 100:+.2f} %" for g in got.values()) + " |")
        print(f"| wall time [s] | {t_mono:.2f} | " + " | ".join(f"{g[1]:.2f}" for g in got.values()) + " |")
        print("| wall time / HydraulicBoom's | 1 | " + " | ".join(f"{g[1] / t_mono:.2f}" for g in got.values()) + " |")
        print("| circuit steps, RHS | | " + " | ".join(f"{g[2]['steps']}, {g[2]['rhs_evals']}" for g in got.values()) + " |")



def render(model, qpos, width: int = 900, height: int = 500) -> np.ndarray:
    """MuJoCo's offscreen picture (RGB, height x width) of the compiled `model` at `qpos`, seen
    along the hinges' axis, the cylinders (tendons) red, boxes orange, planes see-through, the rest
    grey. It needs an offscreen OpenGL that MuJoCo picks when it is imported: MUJOCO_GL=osmesa
    (Debian's libosmesa6, which scripts/setup installs) or egl (a GPU's driver); without one, a
    UsageError."""
    import copy

    m = copy.copy(model)
    m.vis.global_.offwidth, m.vis.global_.offheight = max(width, m.vis.global_.offwidth), max(height, m.vis.global_.offheight)
    m.vis.headlight.ambient[:], m.vis.headlight.diffuse[:], m.vis.headlight.specular[:] = 0.45, 0.55, 0.1
    m.tendon_width[:], m.tendon_rgba[:] = 0.035, [0.85, 0.15, 0.1, 1.0]
    m.geom_rgba[:] = [0.55, 0.6, 0.7, 1.0]
    m.geom_rgba[m.geom_type == mujoco.mjtGeom.mjGEOM_BOX] = [0.95, 0.6, 0.1, 1.0]
    m.geom_rgba[m.geom_type == mujoco.mjtGeom.mjGEOM_PLANE] = [0.5, 0.55, 0.5, 0.3]
    data = mujoco.MjData(m)
    data.qpos[:] = qpos
    mujoco.mj_forward(m, data)
    try:
        renderer = mujoco.Renderer(m, height, width)
    except Exception as e:  # noqa: BLE001 - mujoco.FatalError, or GLFW's without a display
        raise UsageError(f"MuJoCo's renderer found no offscreen OpenGL ({e}): set MUJOCO_GL=osmesa (Debian's "
                         "libosmesa6) or MUJOCO_GL=egl before Python starts") from e
    try:
        solid = m.geom_type != mujoco.mjtGeom.mjGEOM_PLANE  # a plane's bound is infinite
        reach = m.geom_rbound[solid][:, None]
        lo, hi = (data.geom_xpos[solid] - reach).min(axis=0), (data.geom_xpos[solid] + reach).max(axis=0)
        camera = mujoco.MjvCamera()
        camera.lookat[:], camera.distance, camera.azimuth, camera.elevation = (lo + hi) / 2, 1.4 * max(hi - lo), 80, -8
        renderer.update_scene(data, camera)
        return renderer.render().copy()
    finally:
        renderer.close()


def draw(ax, model, qpos, color="0.3") -> None:
    """The model at `qpos` in MuJoCo's x-z plane (the thesis' x-y): capsules as lines, boxes as
    their outline, planes as the ground line, tendons (the cylinders, a rope) through their sites
    (red)."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    for g in range(model.ngeom):
        kind, size, pos, rot = model.geom_type[g], model.geom_size[g], data.geom_xpos[g], data.geom_xmat[g].reshape(3, 3)
        if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
            ends = np.array([pos - rot[:, 2] * size[1], pos + rot[:, 2] * size[1]])
            ax.plot(ends[:, 0], ends[:, 2], color=color, lw=4, solid_capstyle="round")
        elif kind == mujoco.mjtGeom.mjGEOM_BOX:
            corners = np.array([pos + rot @ (size * [a, 0, b]) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1))])
            ax.fill(corners[:, 0], corners[:, 2], color=color, alpha=0.5)
        elif kind == mujoco.mjtGeom.mjGEOM_PLANE:
            ax.axhline(pos[2], color="0.5", lw=1)
    for t in range(model.ntendon):
        wraps = range(model.tendon_adr[t], model.tendon_adr[t] + model.tendon_num[t])
        sites = [model.wrap_objid[w] for w in wraps if model.wrap_type[w] == mujoco.mjtWrap.mjWRAP_SITE]
        points = data.site_xpos[sites]
        ax.plot(points[:, 0], points[:, 2], color="tab:red", lw=2)


if __name__ == "__main__":
    import sys

    from .errors import cli

    sys.exit(cli(main))
