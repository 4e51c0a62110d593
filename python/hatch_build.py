"""The wheel's platform tag (issue 50): scripts/wheel names the platforms of the packed FMUs'
binaries in BOOMSIM_WHEEL_TAG (scripts/wheel_tag.py), so that pip installs the wheel only where
an FMU can run. Without it (the editable install of scripts/setup) hatchling's own tag stays."""

import os

from hatchling.builders.hooks.plugin.interface import BuildHookInterface


class WheelTag(BuildHookInterface):
    def initialize(self, version, build_data):
        tag = os.environ.get("BOOMSIM_WHEEL_TAG")
        if tag:
            build_data["tag"] = tag
            build_data["pure_python"] = False
