"""Metrics of one co-simulation result (definitions in docs/python.md, section Metrics).

All metrics are computed from the recorded rows of Result.data (SI units in, display units
out: bar, mm/s, s, Hz, spool units).
"""

from __future__ import annotations

import math

import numpy as np

from .errors import UsageError

BAR = 1e5
#: Rated flow of the PVG32 spool per unit opening (thesis 2.2.1) and the cylinder areas
#: (parameter list: bore 65 mm, rod 35 mm): the independent expectation of the lowering speed.
Q_RATED = 25e-3 / 60
A_PISTON = math.pi / 4 * 0.065**2
A_ROD_SIDE = math.pi / 4 * (0.065**2 - 0.035**2)
#: Settling band: 2 % (thesis 6.2 and Table 6.3 use the 2 % criterion).
BAND = 0.02
#: Window of the peak-to-peak values [s].
WINDOW = 1.0
#: Motion start: the cylinder lowers faster than this fraction of the expected steady speed.
MOTION_FRACTION = 0.1
#: p3 oscillates when its dominant spectral peak is at least this large [bar] (the same limit as
#: f_dom's comparison in baselines/tolerances.toml).
OSCILLATING = 0.5
#: The CBV counts as open above this opening: a millionth of full opening, far below any flow that
#: matters (Q3 at 1e-6 opening and 100 bar is 1e-5 l/min) and far above the round-off of an
#: integrator that carries u_cbv = 0 as a state (CVode in Model Exchange leaves ~1e-15).
CBV_OPEN = 1e-6
#: Hysteresis of the cycle detection, as a fraction of the swing (ringing near the mean is not a cycle).
HYSTERESIS = 0.1


def expected_velocity(u_ref: float) -> float:
    """Steady lowering speed of the uncompensated, pressure-compensated valve: the rated flow
    times the opening into the rod side, v = -Q_rated |u| / A_rod_side [m/s] (< 0: lowering)."""
    return -Q_RATED * abs(u_ref) / A_ROD_SIDE


def moving_average(y: np.ndarray, n: int) -> np.ndarray:
    """Centred moving average over n samples, the window shrinking at both ends."""
    c = np.concatenate([[0.0], np.cumsum(y)])
    i = np.arange(len(y))
    lo = np.clip(i - n // 2, 0, len(y))
    hi = np.clip(i + n - n // 2, 0, len(y))
    return (c[hi] - c[lo]) / (hi - lo)


def settling_time(t: np.ndarray, y: np.ndarray, band: float = BAND, tail: float = 2.0):
    """2 % settling time: the first time after which |y - y_f(t)| stays within band * |y_f(t)|,
    where the final value y_f(t) is the straight line fitted to the last `tail` seconds
    (p3 drifts slowly as the boom lowers and the load arm changes, so a constant final value
    would call a settled run unsettled). None if y is outside the band at any time of that last
    part: it has not settled within the record."""
    tail_ = t >= t[-1] - tail
    y_f = np.polyval(np.polyfit(t[tail_], y[tail_], 1), t)
    out = np.abs(y - y_f) > band * np.abs(y_f)
    if not out.any():
        return float(t[0])
    last = int(np.nonzero(out)[0][-1])
    if tail_[last]:
        return None
    return float(t[last + 1])


def window_ptp(t: np.ndarray, y: np.ndarray, window: float = WINDOW) -> np.ndarray:
    """Peak-to-peak of y in consecutive windows [0, w), [w, 2w), ..."""
    k = np.floor((t - t[0]) / window + 1e-9).astype(int)
    n = int(round((t[-1] - t[0]) / window))
    return np.array([np.ptp(y[k == i]) for i in range(n) if np.any(k == i)])


def dominant_frequency(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(frequency [Hz], amplitude) of the largest peak of the Hann-windowed spectrum of the
    detrended y, refined by parabolic interpolation of the log magnitude; 0.3 Hz and up (below,
    the slow drift of the lowering motion)."""
    y = y - np.polyval(np.polyfit(t, y, 1), t)
    w = np.hanning(len(y))
    spec = np.abs(np.fft.rfft(y * w)) * 2 / w.sum()
    f = np.fft.rfftfreq(len(y), t[1] - t[0])
    ok = f >= 0.3
    i = int(np.argmax(np.where(ok, spec, 0.0)))
    if 0 < i < len(spec) - 1 and spec[i] > 0 and spec[i] >= max(spec[i - 1], spec[i + 1]):
        a, b, c = np.log(spec[i - 1 : i + 2] + 1e-300)
        d = 0.5 * (a - c) / (a - 2 * b + c) if (a - 2 * b + c) != 0 else 0.0
        return float(f[i] + np.clip(d, -0.5, 0.5) * (f[1] - f[0])), float(spec[i])
    return float(f[i]), float(spec[i])


def whole_cycles(t: np.ndarray, y: np.ndarray, hysteresis: float = HYSTERESIS):
    """(t_a, t_b): the first and last upward crossings of y through its mean, linearly
    interpolated between samples, so that [t_a, t_b] holds whole periods. A crossing counts only
    after y has been below mean - hysteresis * swing. None with fewer than two crossings."""
    mean, low = y.mean(), y.mean() - hysteresis * np.ptp(y)
    ups, armed = [], False
    for i in range(1, len(y)):
        armed = armed or y[i - 1] < low
        if armed and y[i - 1] < mean <= y[i]:
            ups.append(t[i - 1] + (mean - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]))
            armed = False
    return (ups[0], ups[-1]) if len(ups) >= 2 else None


def compute(res) -> dict:
    """The regression metrics of one result (see docs/python.md)."""
    d = res.data
    t, p3, u_comp = d["time"], d["p3"], d["u_comp"]
    if t[-1] - t[0] < WINDOW:
        raise UsageError(f"metrics of a {t[-1] - t[0]:g} s record: they need at least {WINDOW:g} s (the peak-to-peak "
                         "of p3 is taken in windows of that length); run longer (stop_time)")
    u_ss = float(res.scenario["reference"][-1, 1])
    v_exp = expected_velocity(u_ss)
    t_end = t[-1]
    m = {}
    ptp = window_ptp(t, p3) / BAR
    m["p3_pp_max"] = float(ptp.max())
    # the last third of the record (5 s of 15): the sustained oscillation, or what is left of it
    late = t >= t_end - t_end / 3
    m["p3_pp_late"] = float(ptp[-max(1, int(round(t_end / 3 / WINDOW))):].mean())
    ts = settling_time(t, p3)
    # motion start: the load lowers, i.e. oil leaves the piston side through the CBV faster
    # than 10 % of the expected steady flow (before that the piston only creeps while the
    # rising p4 compresses the piston-side oil against the closed CBV)
    q_exp = abs(v_exp) * A_PISTON
    moving = np.nonzero(-d["Q3"] > MOTION_FRACTION * q_exp)[0]
    m["t_motion"] = float(t[moving[0]]) if len(moving) else None
    cbv = np.nonzero(d["cbv.u_cbv"] > CBV_OPEN)[0]
    m["t_cbv_open"] = float(t[cbv[0]]) if len(cbv) else None
    if m["t_motion"] is None:
        ts = None  # a load that never moves has not answered the step
    elif ts is not None:
        ts = max(ts, m["t_motion"])  # p3 may sit in the band before the load moves
    m["t_settle"] = ts
    m["t_settle_motion"] = None if ts is None else max(0.0, ts - m["t_motion"])
    m["v_expected"] = v_exp * 1e3
    f, amp = dominant_frequency(t[late], p3[late])
    # Velocities are displacement / time. While p3 oscillates (U's limit cycle: the velocity
    # swings by +-120 mm/s around its mean) they end at the last whole cycle of p3 and the steady
    # one spans whole cycles: a window with a fraction of a period left over is biased by up to
    # amplitude / (pi f window), +-17 % of U's mean over 5 s, depending on where in the cycle the
    # record ends.
    x = d["cylinder.x"]
    cycles = whole_cycles(t[late], p3[late]) if amp / BAR >= OSCILLATING else None
    t_a, t_b = cycles if cycles else (t[late][0], t_end)
    if m["t_motion"] is not None:
        m["v_mean"] = float((np.interp(t_b, t, x) - x[moving[0]]) / (t_b - m["t_motion"]) * 1e3)
    else:
        m["v_mean"] = 0.0
    m["v_steady"] = float((np.interp(t_b, t, x) - np.interp(t_a, t, x)) / (t_b - t_a) * 1e3)
    m["f_dom"] = f
    m["f_dom_amp"] = amp / BAR
    after = t >= (ts if ts is not None else t_end - t_end / 3)
    m["u_comp_rms"] = float(np.sqrt(np.mean(u_comp[after] ** 2)))
    m["u_comp_max"] = float(u_comp.max())
    return m


#: Units and one-line definitions, for the reports.
DEFINITIONS = {
    "p3_pp_max": ("bar", "largest p3 peak-to-peak of the 1 s windows"),
    "p3_pp_late": ("bar", "mean p3 peak-to-peak of the 1 s windows of the last third (10-15 s)"),
    "t_settle": ("s", "2 % settling time of p3 to the line fitted to its last 2 s (- = not settled)"),
    "t_settle_motion": ("s", "settling time counted from the motion start (thesis 6.2 counts from the step)"),
    "t_motion": ("s", "motion start: CBV outflow above 10 % of the expected steady flow"),
    "t_cbv_open": ("s", "first opening of the CBV's load-holding valve"),
    "v_expected": ("mm/s", "-Q_rated |u_ref| / A_rod_side"),
    "v_mean": ("mm/s", "mean velocity from the motion start to the end, or to the last whole p3 cycle when p3 oscillates (displacement / time)"),
    "v_steady": ("mm/s", "mean velocity over the last third, or over its whole p3 cycles when p3 oscillates (displacement / time)"),
    "f_dom": ("Hz", "dominant frequency of p3 over the last third (>= 0.3 Hz)"),
    "f_dom_amp": ("bar", "amplitude of that spectral peak"),
    "u_comp_rms": ("1", "RMS of u_comp after the settling time (last third if not settled)"),
    "u_comp_max": ("1", "largest u_comp (> 0 closes the valve while lowering)"),
}
