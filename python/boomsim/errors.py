"""The errors the package raises for its users, and the command lines' handling of them."""

from __future__ import annotations

import pathlib
import sys


class UsageError(Exception):
    """A wrong argument or a missing file: one line for the user, naming the value and the fix."""


class Skip(Exception):
    """A scenario variant that cannot run with the FMUs at hand (reason in the message)."""


def cli(main) -> int:
    """Runs a command line's `main()`; a UsageError (a missing FMU, an unknown scenario) becomes
    one line on stderr and exit status 2 instead of a traceback."""
    try:
        return main() or 0
    except UsageError as e:
        print(f"{pathlib.Path(sys.argv[0]).name}: error: {e}", file=sys.stderr)
        return 2


def parse_params(ap, pairs: list[str]) -> dict:
    """The FMU parameters of a command's repeatable `--param NAME=VALUE` as {name: number, or
    the name of an Enumeration's item}; a pair that is not one ends the command through
    `ap.error` with one line."""
    def value(text: str):
        try:
            return float(text)
        except ValueError:
            return text
    try:
        return {k: value(v) for k, v in (p.split("=", 1) for p in pairs)}
    except ValueError:
        ap.error(f"--param {' '.join(pairs)}: expected NAME=VALUE")
