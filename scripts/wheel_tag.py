"""The wheel's tag for the platforms its .fmu binaries run on (issue 50): py3-none- and, per
binary directory of the packed FMUs, the platform tag pip checks before it installs. Linux:
manylinux_2_<N> with N the newest glibc symbol version any of the .so files needs (read with
readelf, which reads ELF files of any architecture); Windows: win_amd64. On a platform outside
the set pip refuses the wheel ("not a supported wheel on this platform") instead of installing
FMUs without a binary for it. Prints the tag.

    .venv/bin/python scripts/wheel_tag.py target/fmu/*.fmu target/fmu/fmi3/*.fmu
"""

import re
import subprocess
import sys
import tempfile
import zipfile

#: FMI binary directory -> (wheel platform tag, with {glibc} for Linux).
PLATFORMS = {"x86_64-linux": "manylinux_{glibc}_x86_64", "aarch64-linux": "manylinux_{glibc}_aarch64",
             "x86_64-windows": "win_amd64", "linux64": "manylinux_{glibc}_x86_64", "win64": "win_amd64"}


def glibc(data: bytes) -> tuple[int, int]:
    """The newest GLIBC_x.y symbol version an ELF shared library needs."""
    with tempfile.NamedTemporaryFile(suffix=".so") as f:
        f.write(data)
        f.flush()
        out = subprocess.run(["readelf", "-W", "--version-info", f.name], capture_output=True, text=True,
                             check=True).stdout
    return max((tuple(int(x) for x in v.split(".")) for v in re.findall(r"GLIBC_(\d+\.\d+)", out)), default=(2, 17))


def main(paths: list[str]) -> None:
    platforms, newest = set(), (2, 17)
    for path in paths:
        with zipfile.ZipFile(path) as z:
            for name in z.namelist():
                parts = name.split("/")
                if len(parts) == 3 and parts[0] == "binaries" and parts[2]:
                    if parts[1] not in PLATFORMS:
                        sys.exit(f"wheel_tag.py: {path}: no wheel platform for binaries/{parts[1]}")
                    platforms.add(parts[1])
                    if parts[2].endswith(".so"):
                        newest = max(newest, glibc(z.read(name)))
    tags = sorted({PLATFORMS[p].format(glibc=f"{newest[0]}_{newest[1]}") for p in platforms})
    print("py3-none-" + ".".join(tags))


if __name__ == "__main__":
    main(sys.argv[1:])
