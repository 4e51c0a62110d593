"""The one way the co-simulation loop talks to mechanics: per cylinder, the stroke and velocity out
and the rod force (plain port) or the circuit's wave c_h (TLM port) in, one step of h at a time.

A mechanics is a class with four methods (the port and its signs: docs/coupling.md):

    holding_force()   the force along each cylinder that holds the mechanics at rest at its start [N]
    motion()          (x, v): each cylinder's stroke [m] and rate [m/s], > 0 extending, now
    advance(t, h, u)  one communication step from t under u per cylinder, held over the step:
                      plain: the rod force F pushing the rod out; TLM: the wave c_h, the mechanics
                      pushed by F_M = c_h - Z_c v_M inside its own integrator (the -Z_c v term is
                      damping: implicit where the integrator can)
    wave()            TLM: c_m per cylinder at the step end; computed here from motion() for an
                      engine that knows nothing of waves, read from an FMU that emits its own

`BoomMechanicsFmu` (boomsim's BoomMechanics FMU) and `boomsim.mujoco.MujocoMechanics` are the two;
a third engine (PyBullet, Chrono, a Modelica FMU) is one more subclass.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from .errors import UsageError
from .fmus import Direct

PORTS = ("plain", "tlm")


class Mechanics(ABC):
    """Mechanics driven through the port `port` ("plain" or "tlm") with the TLM impedance `z_c`
    [N s/m] and wave filter `alpha` of each cylinder (HydraulicCircuit's port.Z_c and port.alpha:
    equal on both sides of the line)."""

    def __init__(self, port: str, z_c=0.0, alpha=0.0):
        if port not in PORTS:
            raise UsageError(f"port = {port!r}: must be one of {PORTS}")
        self.port = port
        # per cylinder (a number: one cylinder)
        self.z_c, self.alpha = ([float(a) for a in np.atleast_1d(b)] for b in (z_c, alpha))
        self._c_m = None

    @abstractmethod
    def holding_force(self) -> np.ndarray:
        """The force along each cylinder that holds the mechanics at rest at its start [N]."""

    @abstractmethod
    def motion(self) -> tuple[list[float], list[float]]:
        """(x, v): each cylinder's stroke [m] and rate [m/s] now."""

    @abstractmethod
    def advance(self, t: float, h: float, u) -> None:
        """One step from `t` to `t + h` under the port input `u` (force or wave c_h), held."""

    def step(self, t: float, h: float, u) -> None:
        """`advance`, then (TLM) the wave emitted from the state reached: c_m = F_M - Z_c v with
        F_M = c_h - Z_c v (the line force at the step end), filtered by alpha as the circuit filters
        its own (c <- alpha c + (1 - alpha) c_new). Per cylinder in Python floats: for one or two
        cylinders numpy's per-call cost is most of a step's."""
        self.advance(t, h, u)
        if self.port == "tlm":
            _, v = self.motion()
            self._c_m = [a * c + (1.0 - a) * (ui - 2.0 * z * vi)
                         for a, c, ui, z, vi in zip(self.alpha, self.wave(), u, self.z_c, v)]

    def wave(self) -> list[float]:
        """TLM: the wave c_m to the circuit; at the start the holding force (both sides at rest)."""
        if self._c_m is None:
            self._c_m = [float(f) for f in self.holding_force()]
        return self._c_m


class BoomMechanicsFmu(Mechanics):
    """boomsim's BoomMechanics FMU (FMI 2.0 Co-Simulation through fmpy), initialised: one cylinder,
    its own port (port.coupling) and wave."""

    def __init__(self, fmu_file, slave, port: str, z_c: float = 0.0, alpha: float = 0.0):
        super().__init__(port, z_c, alpha)
        self.f, self.s, vr, calls = fmu_file, slave, fmu_file.vr, Direct(slave)
        self._input = calls.setter([vr["port.c_h"] if port == "tlm" else vr["cylinder.F"]])
        self._motion, self._wave = calls.getter([vr["cylinder.x"], vr["cylinder.v"]]), calls.getter([vr["port.c_m"]])
        self._step = calls.stepper()

    def holding_force(self) -> np.ndarray:
        return np.array(self.s.getReal([self.f.vr["start.F"]]))

    def motion(self) -> tuple[list[float], list[float]]:
        x, v = self._motion()
        return [x], [v]

    def advance(self, t: float, h: float, u) -> None:
        self._input(u)
        self._step(t, h)

    def step(self, t: float, h: float, u) -> None:
        """The FMU emits its own wave."""
        self.advance(t, h, u)

    def wave(self) -> list[float]:
        return self._wave()[:]
