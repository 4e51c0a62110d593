"""Scenes beyond boomsim's own mechanics, with MuJoCo (docs/mujoco.md):

    touchdown   the thesis' boom sets its payload down on the ground: the payload hangs on a rope
                from the arm's end (a tendon that only pulls), MuJoCo's contact takes it over
    knuckle     a knuckle boom: the thesis' boom with a jib hinged at its end, two cylinders, two
                HydraulicCircuit instances and two valve commands; a closed motion and its energy
                balance

    boomsim-mujoco-scene touchdown|knuckle [--out PNG] [--render PNG]   runs the scene, writes its
        figure (and MuJoCo's picture of its end: MUJOCO_GL=osmesa or egl, boomsim.mujoco.render)
"""

from __future__ import annotations

import dataclasses

import numpy as np

import mujoco

from . import mujoco as bm
from .fmus import FmuFile

#: The rope's stretch at the start [m]: MuJoCo's limit acts once the length passes its range.
ROPE_STRETCH = 1e-3


@dataclasses.dataclass
class Scene:
    """A scene's MJCF, its cylinders, the monitor that records what its checks need, and how long it runs."""

    name: str
    mjcf: object
    cylinders: list
    monitor: object
    columns: tuple
    stop_time: float
    record_every: int | None = None


def _payload_mass() -> float:
    return float(FmuFile.get("BoomMechanics").vars["payload.m"].start)


def touchdown(start_stroke: float = 0.48, drop: float = 0.25, rope: float = 0.5, close_at: float = 9.0,
              timestep: float = 5e-4) -> Scene:
    """The arm of the thesis (its payload.m = 0 in the body) with the payload, BoomMechanics'
    payload.m, a cube of bm.PAYLOAD_HALF on a rope of `rope` m from the payload's point on the arm;
    the ground `drop` m below the cube at the start. The valve lowers as in experiment B (u_ref =
    -0.05 with the corrected feedback) and closes at `close_at` s, after touchdown. Monitor:
    contact force on the cube (normal, summed) [N], its height [m], the rope's length [m]."""
    g = bm.boom_geometry(start_stroke, {"payload.m": 0.0})
    spec = bm.mjcf_spec(bm.boom_mjcf(start_stroke, {"payload.m": 0.0}, timestep=timestep, integrator="implicitfast"))
    hook_local = spec.geom("payload").pos.copy()
    spec.delete(spec.geom("payload"))
    arm = spec.body("boom")
    arm.add_site(name="hook", pos=hook_local, size=[0.02, 0, 0])
    probe = spec.compile()
    data = mujoco.MjData(probe)
    data.qpos[0] = g["boom.theta"]
    mujoco.mj_kinematics(probe, data)
    hook = data.site_xpos[mujoco.mj_name2id(probe, mujoco.mjtObj.mjOBJ_SITE, "hook")].copy()
    centre = hook - [0.0, 0.0, rope + bm.PAYLOAD_HALF + ROPE_STRETCH]
    m = _payload_mass()
    cube = spec.worldbody.add_body(name="payload", pos=centre, mass=m, explicitinertial=True, ipos=[0.0, 0.0, 0.0],
                                   inertia=[m * (2 * bm.PAYLOAD_HALF) ** 2 / 6] * 3)
    cube.add_freejoint(name="payload.free")
    cube.add_geom(name="payload", type=mujoco.mjtGeom.mjGEOM_BOX, size=[bm.PAYLOAD_HALF] * 3, contype=1, conaffinity=1)
    cube.add_site(name="payload.top", pos=[0, 0, bm.PAYLOAD_HALF], size=[0.02, 0, 0])
    spec.worldbody.add_geom(name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[6, 3, 0.1],
                            pos=[0, 0, centre[2] - bm.PAYLOAD_HALF - drop], contype=1, conaffinity=1)
    r = spec.add_tendon(name="rope", limited=True, range=[0.0, rope])
    r.wrap_site("hook")
    r.wrap_site("payload.top")
    spec.key("start").qpos = [g["boom.theta"], *centre, 1.0, 0.0, 0.0, 0.0]
    cylinder = bm.thesis_cylinder([[0.0, -0.05], [close_at, -0.05], [close_at, 0.0], [close_at + 1, 0.0]],
                                  {"enable": True, "K_f": 1.24e-11, "omega_f": 35.8}, params={"payload.m": 0.0})
    return Scene("touchdown", spec, [cylinder], _touchdown_monitor, ("contact force [N]", "payload z [m]",
                                                                       "rope length [m]"), close_at + 3.0)


def _touchdown_monitor(_t, model, data):
    cube = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "payload")
    force, frame = 0.0, np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        if cube in (c.geom1, c.geom2):
            mujoco.mj_contactForce(model, data, i, frame)
            force += frame[0]
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "payload")
    rope = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TENDON, "rope")
    return force, data.xpos[body, 2], data.ten_length[rope]


def run(scene: Scene, coupling: str = "tlm", step: float | None = None):
    """The scene coupled (boomsim.mujoco.run) from rest at its keyframe."""
    return bm.run(scene.mjcf, scene.cylinders, coupling, step, scene.stop_time, monitor=scene.monitor,
                  record_every=scene.record_every)


@dataclasses.dataclass(frozen=True)
class Jib:
    """The knuckle boom's jib and its cylinder: the example's own numbers (the thesis has one boom),
    chosen for a small knuckle crane that the thesis' cylinder and circuit can work: a 1.5 m, 60 kg
    jib with 150 kg at its end (the two weigh about what the thesis' 383 kg payload does at the
    boom's end); the cylinder's barrel pin 0.8 m back along the boom and 0.35 m below its axis,
    its rod pin 0.35 m below the jib's hinge (a 0.27 m lever at the start), 0.5 m pin to pin
    retracted; at the start the jib hangs 0.6 rad below the boom's axis."""

    length: float = 1.5
    mass: float = 60.0
    load: float = 150.0
    pin_back: float = 0.8
    pin_below: float = 0.35
    l_retracted: float = 0.5
    start_angle: float = -0.6


#: Both valves' commands of the knuckle scene ([t, u_ref] rows): the boom lifts at 0.4 from 0.2 to
#: 1.7 s, the jib from 0.5 to 2.0 s; both lower at -0.4 from 2.5 and 3.0 s until they are back
#: near the start (lowering is faster at the same command), then hold.
KNUCKLE_COMMANDS = {"boom": [[0.0, 0.0], [0.2, 0.0], [0.2, 0.4], [1.7, 0.4], [1.7, 0.0], [2.5, 0.0], [2.5, -0.4],
                             [3.9, -0.4], [3.9, 0.0]],
                    "jib": [[0.0, 0.0], [0.5, 0.0], [0.5, 0.4], [2.0, 0.4], [2.0, 0.0], [3.0, 0.0], [3.0, -0.4],
                            [4.5, -0.4], [4.5, 0.0]]}


def knuckle(start_stroke: float = 0.30, jib: Jib = Jib(), timestep: float = 5e-4) -> Scene:
    """The thesis' boom (its payload.m = 0 in the body) at `start_stroke` with `jib` hinged at the
    payload's point (joint `jib.phi`, its angle to the boom, > 0 up), the jib's load a cube at its
    end. Both cylinders are the thesis' cylinder and circuit with its feedback (B's gains), their
    rods' mass in the circuits only (port.m): MuJoCo's energy is then the whole machine's. The
    commands are KNUCKLE_COMMANDS. Recorded every step; monitor: MuJoCo's kinetic + potential
    energy [J] (mjENBL_ENERGY)."""
    params = {"payload.m": 0.0}
    g = bm.boom_geometry(start_stroke, params)
    spec = bm.mjcf_spec(bm.boom_mjcf(start_stroke, params, timestep=timestep))
    spec.option.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    hinge = spec.geom("payload").pos.copy()
    spec.delete(spec.geom("payload"))
    boom = spec.body("boom")
    lower = [hinge[0] - jib.pin_back, 0.0, hinge[2] - jib.pin_below]
    boom.add_site(name="jib.lower", pos=lower, size=[0.03, 0, 0])
    # the pins' brackets, drawn only (no mass, no contact)
    boom.add_geom(name="jib.lower.bracket", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[lower[0], 0, 0, *lower],
                  size=[0.02, 0, 0], contype=0, conaffinity=0, mass=0.0)
    arm = boom.add_body(name="jib", pos=hinge, mass=jib.mass, explicitinertial=True, ipos=[jib.length / 2, 0.0, 0.0],
                        inertia=[jib.mass * jib.length ** 2 / 12] * 3)
    arm.add_joint(name="jib.phi", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, -1, 0])
    arm.add_geom(name="jib", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, jib.length, 0, 0], size=[0.04, 0, 0],
                 contype=0, conaffinity=0)
    arm.add_site(name="jib.upper", pos=[0.0, 0.0, -jib.pin_below], size=[0.03, 0, 0])
    arm.add_geom(name="jib.upper.bracket", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, 0, 0, -jib.pin_below],
                 size=[0.02, 0, 0], contype=0, conaffinity=0, mass=0.0)
    load = arm.add_body(name="jib.load", pos=[jib.length, 0.0, 0.0], mass=jib.load, explicitinertial=True,
                        ipos=[0.0, 0.0, 0.0], inertia=[jib.load * (2 * bm.PAYLOAD_HALF) ** 2 / 6] * 3)
    load.add_geom(name="jib.load", type=mujoco.mjtGeom.mjGEOM_BOX, size=[bm.PAYLOAD_HALF] * 3, contype=0, conaffinity=0)
    spec.key("start").qpos = [g["boom.theta"], jib.start_angle]
    feedback = {"enable": True, "K_f": 1.24e-11, "omega_f": 35.8}
    cylinders = [dataclasses.replace(bm.thesis_cylinder(KNUCKLE_COMMANDS["boom"], feedback, params=params), rod_mass=0.0),
                 bm.Cylinder("jib", "jib.lower", "jib.upper", jib.l_retracted, KNUCKLE_COMMANDS["jib"], feedback)]
    return Scene("knuckle", spec, cylinders, _energy_monitor, ("mechanical energy [J]",), 6.5, record_every=1)


def _energy_monitor(_t, _model, data):
    return (data.energy[0] + data.energy[1],)


def pressure_force(run, cylinder) -> np.ndarray:
    """The pressure force on a cylinder's piston over a run, p3 A - p4 mu_c A (eq. 2.60-2.61),
    A and mu_c A from its circuit's cylinder.d_piston and d_rod [N]."""
    circuit = FmuFile.get("HydraulicCircuit").vars
    d_p, d_r = (cylinder.circuit.get(k, float(circuit[k].start)) for k in ("cylinder.d_piston", "cylinder.d_rod"))
    r = run.results[cylinder.name]
    return r["p3"] * np.pi / 4 * d_p ** 2 - r["p4"] * np.pi / 4 * (d_p ** 2 - d_r ** 2)


def powers(run) -> tuple[np.ndarray, np.ndarray]:
    """(hydraulic, friction) power of all cylinders over a run [W]: the pressure forces' power
    on the pistons, sum of pressure_force v, and the cylinders' friction's, sum of F_fr v
    (HydraulicCircuit's cylinder.F_fr, eq. 2.65). The circuit's own force balance holds by its
    construction (its rod force is the pressure force less F_fr), so a balance of these against
    MuJoCo's energy checks what crosses the port: the TLM line's exchange and MuJoCo's integration."""
    hydraulic = friction = 0.0
    for c in run.cylinders:
        r = run.results[c.name]
        hydraulic = hydraulic + pressure_force(run, c) * r["cylinder.v"]
        friction = friction + r["cylinder.F_fr"] * r["cylinder.v"]
    return hydraulic, friction


def work(power: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The work of `power` from t[0] to each t, by the trapezoid rule [J]."""
    return np.concatenate([[0.0], np.cumsum((power[1:] + power[:-1]) / 2 * np.diff(t))])


def energy_balance(run) -> dict:
    """The energy of a run recorded every step [J], `powers` integrated (`work`):
    `hydraulic`, the pressure forces' work on the pistons; `friction`, the work the cylinders'
    friction dissipates; `mechanical`, the change of MuJoCo's kinetic + potential energy (the
    monitor's first column); `throughput`, the integral of |hydraulic power| (the scale of the
    balance); `imbalance` = hydraulic - friction - mechanical."""
    t = run.results[run.cylinders[0].name]["time"]
    power, lost = powers(run)
    hydraulic, friction, throughput = (work(p, t)[-1] for p in (power, lost, np.abs(power)))
    mechanical = run.monitored[-1, 0] - run.monitored[0, 0]
    return {"hydraulic": hydraulic, "friction": friction, "mechanical": mechanical, "throughput": throughput,
            "imbalance": hydraulic - friction - mechanical}


def plot_touchdown(run, path) -> None:
    """The touchdown figure: the scene at the start, at touchdown and at the end (MuJoCo's bodies
    in the x-z plane), the cylinder's pressures, the CBV's opening and the contact force."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .figures import save

    res, mon = run.results["boom"], run.monitored
    t = res["time"]
    touch = int(np.argmax(mon[:, 0] > 0)) if np.any(mon[:, 0] > 0) else len(t) - 1
    fig, (scene, pressure, force) = plt.subplots(1, 3, figsize=(15, 4.5), layout="constrained")
    for i, shade in ((0, "0.75"), (touch, "0.5"), (len(t) - 1, "0.2")):
        bm.draw(scene, run.model, run.qpos[i], shade)
    scene.set(aspect="equal", xlabel="x [m]", ylabel="z [m]",
              title=f"t = 0, {t[touch]:.2f} s (touchdown), {t[-1]:.0f} s: light to dark")
    pressure.plot(t, res["p3"] / 1e5, label="p3 (piston side)")
    pressure.plot(t, res["p4"] / 1e5, label="p4 (rod side)")
    pressure.set(xlabel="time [s]", ylabel="pressure [bar]", title="cylinder pressures")
    pressure.legend()
    force.plot(t, mon[:, 0] / 1e3, color="tab:green", label="contact force on the payload")
    force.set(xlabel="time [s]", ylabel="force [kN]", title="contact force and CBV opening")
    cbv = force.twinx()
    cbv.plot(t, res["cbv.u_cbv"], color="tab:purple", label="CBV opening")
    cbv.set_ylabel("CBV opening [-]")
    force.legend(loc="upper left")
    cbv.legend(loc="center left")
    for ax in (pressure, force):
        ax.axvline(t[touch], color="0.6", ls=":")
    save(fig, path, dpi=110)
    plt.close(fig)


def plot_knuckle(run, path) -> None:
    """The knuckle figure: the machine at the start, at its highest and at the end, both
    cylinders' strokes and commands, their piston-side pressures, and the energy balance over
    time (the pistons' work against friction + MuJoCo's energy change)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .figures import save

    boom, jib = run.results["boom"], run.results["jib"]
    t = boom["time"]
    top = int(np.argmax(boom["cylinder.x"] + jib["cylinder.x"]))
    fig, axes = plt.subplots(1, 4, figsize=(19, 4.5), layout="constrained")
    scene, stroke, pressure, energy = axes
    for i, shade in ((0, "0.75"), (top, "0.45"), (len(t) - 1, "0.2")):
        bm.draw(scene, run.model, run.qpos[i], shade)
    scene.set(aspect="equal", xlabel="x [m]", ylabel="z [m]",
              title=f"t = 0, {t[top]:.1f} s (highest), {t[-1]:.1f} s: light to dark")
    for r, name in ((boom, "boom"), (jib, "jib")):
        line, = stroke.plot(t, r["cylinder.x"] * 1e3, label=f"{name} stroke")
        pressure.plot(t, r["p3"] / 1e5, color=line.get_color(), label=f"{name} p3")
        pressure.plot(t, r["p4"] / 1e5, color=line.get_color(), ls="--", label=f"{name} p4")
    command = stroke.twinx()
    for r, name, style in ((boom, "boom", "-"), (jib, "jib", "--")):
        command.plot(t, r["u_ref"], color="0.5", ls=style, lw=1, label=f"{name} command")
    command.set_ylabel("valve command u_ref [-]")
    stroke.set(xlabel="time [s]", ylabel="stroke [mm]", title="strokes and valve commands")
    stroke.legend(loc="upper left")
    command.legend(loc="upper right")
    pressure.set(xlabel="time [s]", ylabel="pressure [bar]", title="cylinder pressures")
    pressure.legend(fontsize=8)
    power, lost = powers(run)
    energy.plot(t, work(power, t) / 1e3, label="work of the pressure forces")
    energy.plot(t, (work(lost, t) + run.monitored[:, 0] - run.monitored[0, 0]) / 1e3, ls="--",
                label="friction + MuJoCo's energy change")
    b = energy_balance(run)
    energy.set(xlabel="time [s]", ylabel="energy [kJ]",
               title=f"energy balance: {b['imbalance']:+.3f} J of {b['throughput'] / 1e3:.2f} kJ throughput")
    energy.legend()
    save(fig, path, dpi=110)
    plt.close(fig)


def main(argv=None):
    import argparse

    from .paths import OUT

    ap = argparse.ArgumentParser(description="A MuJoCo scene driven by HydraulicCircuit: runs it, writes its figure")
    ap.add_argument("scene", choices=("touchdown", "knuckle"))
    ap.add_argument("--out", default=None, help="the figure (default: out/mujoco_<scene>.png)")
    ap.add_argument("--render", default=None, help="MuJoCo's offscreen picture of the scene's end, a PNG "
                    "(needs MUJOCO_GL=osmesa or egl)")
    args = ap.parse_args(argv)
    out = args.out or OUT / f"mujoco_{args.scene}.png"
    scene = globals()[args.scene]()
    result = run(scene)
    globals()[f"plot_{args.scene}"](result, out)
    print(f"wrote {out}")
    if args.render:
        import matplotlib.pyplot as plt

        plt.imsave(args.render, bm.render(result.model, result.qpos[-1]))
        print(f"wrote {args.render}")


if __name__ == "__main__":
    import sys

    from .errors import cli

    sys.exit(cli(main))
