"""Scenes beyond boomsim's own mechanics, with MuJoCo (docs/mujoco.md):

    touchdown   the thesis' boom sets its payload down on the ground: the payload hangs on a rope
                from the arm's end (a tendon that only pulls), MuJoCo's contact takes it over

    boomsim-mujoco-scene touchdown [--out PNG]   runs the scene, writes its figure
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
    return bm.run(scene.mjcf, scene.cylinders, coupling, step, scene.stop_time, monitor=scene.monitor)


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


def main(argv=None):
    import argparse

    from .paths import OUT

    ap = argparse.ArgumentParser(description="A MuJoCo scene driven by HydraulicCircuit: runs it, writes its figure")
    ap.add_argument("scene", choices=("touchdown",))
    ap.add_argument("--out", default=None, help="the figure (default: out/mujoco_<scene>.png)")
    args = ap.parse_args(argv)
    out = args.out or OUT / f"mujoco_{args.scene}.png"
    scene = globals()[args.scene]()
    globals()[f"plot_{args.scene}"](run(scene), out)
    print(f"wrote {out}")


if __name__ == "__main__":
    import sys

    from .errors import cli

    sys.exit(cli(main))
