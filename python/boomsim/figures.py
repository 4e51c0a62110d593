"""Saving the scripts' figures so that a user can read them: every title, legend and tick label
inside the canvas, every axis that shows data labelled with its unit in brackets ("[bar]", "[-]"
for a dimensionless one) on the axis itself or on one it shares. A figure that breaks a rule is
saved all the same with a warning; under the tests (BOOMSIM_STRICT_FIGURES=1, set by
tests/python/conftest.py for every script they run) it is an error naming the rule."""

from __future__ import annotations

import os
import re
import warnings

#: An axis label's unit: the text in brackets.
UNIT = re.compile(r"\[[^\]]+\]")


def problems(fig) -> list[str]:
    """What `fig`, drawn (laid out), breaks, one line each."""
    found = []
    tight = fig.get_tightbbox(fig.canvas.get_renderer())
    width, height = fig.get_size_inches()
    if tight.x0 < -0.01 or tight.y0 < -0.01 or tight.x1 > width + 0.01 or tight.y1 > height + 0.01:
        found.append(f"text outside the canvas: its extent is {tight.bounds} in a {width:g} x {height:g} in figure")
    for ax in fig.axes:
        if not ax.get_visible() or not (ax.has_data() or ax.images or ax.collections):
            continue
        if getattr(ax, "_colorbar", None) is not None:  # a colour bar: its one labelled axis
            if not UNIT.search(ax.get_xlabel() + ax.get_ylabel()):
                found.append(f"a colour bar has no unit in brackets ({ax.get_ylabel() or ax.get_xlabel()!r})")
            continue
        for axis, label, shared in (("x", ax.get_xlabel, ax.get_shared_x_axes), ("y", ax.get_ylabel, ax.get_shared_y_axes)):
            labels = [a.get_xlabel() if axis == "x" else a.get_ylabel() for a in shared().get_siblings(ax)]
            if not any(UNIT.search(t) for t in labels + [label()]):
                title = ax.get_title() or fig.get_suptitle()[:40]
                found.append(f'the {axis} axis of "{title}" has no unit in brackets ({label()!r})')
    return found


def save(fig, path, **kwargs):
    """`fig.savefig(path, **kwargs)`, then [`problems`] of the figure it drew (no second drawing:
    a third of a plot's time): a warning, or an error under the tests."""
    fig.savefig(path, **kwargs)
    found = problems(fig)
    if found:
        message = f"{path}: " + "; ".join(found)
        if os.environ.get("BOOMSIM_STRICT_FIGURES") == "1":
            raise AssertionError(message)
        warnings.warn(message, stacklevel=2)
