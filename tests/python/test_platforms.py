"""Every FMU carries linux64, win64 and aarch64-linux binaries, and each runs: the C host of
tests/host/fmu_host.c, compiled with gcc, MinGW-w64 and aarch64 gcc, loads the library natively,
under wine64 and under qemu-aarch64, and the numbers must agree with linux64. The same for the
FMI 3.0 .fmu (binaries/x86_64-linux, x86_64-windows, aarch64-linux: the same library), through the
host's FMI 3.0 entry points (`fmu_host --fmi3`), and there FMI 3.0 must equal FMI 2.0 on the same
platform bit for bit: the same binary runs the same code (runtime/src/fmu/calls.rs) for both versions' calls.

Needs `boomsim pack --platforms all` (scripts/test does it) and scripts/setup-cross.

What agrees how well, and why:
- the controller's outputs to 1e-12 relative: a closed-form filter (exp, arithmetic), identical
  code; only libm's exp may differ, by an ulp;
- the plants' outputs, at rtol 1e-6, to 1e-5 of each output's largest magnitude over the run (U:
  5e-5, below), or
  to twice linux64's own global error in that output where it is larger: the same code, but the
  platforms' libm (glibc on x86-64 and aarch64, msvcrt on Windows) differs in the last bit of exp,
  pow, tanh, sin/cos/acos, and the adaptive Radau IIA integrator turns such differences into
  different step sequences: two integrations of the same ODE, each within its global error of the
  converged solution, so they may differ by that much. The global error is measured against the
  same run at rtol 1e-10 on linux64; it is a few rtol except where the controller's high-pass
  filter differentiates the integrator's error (B with the flexible arm: 1e-4 of Q4's range as
  the spool opens); in U, where no input changes, the integrator's steps pass the communication
  points and the outputs there come from the steps' collocation polynomials (continuous output of
  order 3): measured at rtol 1e-6, each platform's outputs within 2.7e-5 of their range of the
  converged run (aarch64, p2; linux64 7.4e-6), so U's floor is 5e-5. A real defect (a wrong ABI, a mis-linked math function, a truncated constant)
  is far larger. The largest differences are printed (pytest -s) and quoted in the README."""

import math
import os
import pathlib
import shutil
import subprocess
import xml.etree.ElementTree as ET
import zipfile

import fmpy
from fmpy.validation import validate_fmu
import pytest

from conftest import EXPORTED, fmu_path

ROOT = pathlib.Path(__file__).resolve().parents[2]
HOST_SOURCE = ROOT / "tests" / "host" / "fmu_host.c"
PLATFORMS = ("linux64", "win64", "aarch64-linux")
IDS = ("PressureFeedbackController", "HydraulicBoom", "HydraulicCircuit", "BoomMechanics")
WINE = "/usr/lib/wine/wine64"
QEMU = ["qemu-aarch64", "-L", "/usr/aarch64-linux-gnu"]
SUFFIX = {"linux64": ".so", "win64": ".dll", "aarch64-linux": ".so"}
#: The binaries/ folder of each platform in an FMI 3.0 .fmu (FMI 3.0, 2.5.1.1: platform tuples).
TUPLE = {"linux64": "x86_64-linux", "win64": "x86_64-windows", "aarch64-linux": "aarch64-linux"}
FMI_VERSIONS = (2, 3)
#: The libraries a binary may import: what every Windows 10 and every glibc Linux has.
ALLOWED_DLLS = {"kernel32.dll", "ntdll.dll", "msvcrt.dll", "userenv.dll", "ws2_32.dll", "bcryptprimitives.dll"}
ALLOWED_SO = {"libc.so.6", "libm.so.6", "libgcc_s.so.1", "ld-linux-aarch64.so.1", "ld-linux-x86-64.so.2"}

def fmu3_path(ident):
    path = ROOT / "target" / "fmu" / "fmi3" / f"{ident}.fmu"
    assert path.exists(), f"{path} is missing: run target/release/boomsim pack"
    return path


@pytest.fixture(scope="module")
def unpacked(tmp_path_factory):
    """{(fmi, identifier): (folder, GUID or instantiationToken, {platform: library})}: every FMU
    of both versions unzipped."""
    out = {}
    for ident in IDS:
        for fmi, path, attr in ((2, fmu_path(ident), "guid"), (3, fmu3_path(ident), "instantiationToken")):
            d = tmp_path_factory.mktemp(f"{ident}-fmi{fmi}")
            with zipfile.ZipFile(path) as z:
                z.extractall(d)
            libs = {p: d / "binaries" / (TUPLE[p] if fmi == 3 else p) / (ident + SUFFIX[p]) for p in PLATFORMS}
            out[fmi, ident] = (d, ET.parse(d / "modelDescription.xml").getroot().get(attr), libs)
    return out


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """The C host for each platform and the command prefix that runs it."""
    d = tmp_path_factory.mktemp("host")
    compilers = {  # compiler, executable, libraries, runner
        "linux64": ("gcc", "fmu_host", ["-ldl"], []),
        "win64": ("x86_64-w64-mingw32-gcc", "fmu_host.exe", [], [WINE]),
        "aarch64-linux": ("aarch64-linux-gnu-gcc", "fmu_host_aarch64", ["-ldl"], QEMU),
    }
    out = {}
    for platform, (cc, name, libs, runner) in compilers.items():
        exe = d / name
        subprocess.run([cc, "-O2", "-std=c99", "-Wall", "-Werror", "-o", str(exe), str(HOST_SOURCE)] + libs, check=True)
        out[platform] = runner + [str(exe)]
    return out


def run(hosts, unpacked, platform, steps, fmus, ops, fmi=2, h="0.001", early=None):
    """fmu_host's printed rows (lists of floats, exact: printed with 17 digits) for the FMI `fmi`
    FMUs `fmus` on `platform`, stepped by `h` seconds; with a list `early`, the times of the early
    returns it reported are appended to it."""
    args = (["--fmi3"] if fmi == 3 else []) + [str(steps), h]
    for ident in fmus:
        _, token, libs = unpacked[fmi, ident]
        args += [str(libs[platform]), token]
    env = dict(os.environ, WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    r = subprocess.run(hosts[platform] + args + ["--"] + ops, capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, f"{platform}, FMI {fmi}: {r.stderr}"
    if early is not None:
        reported = [line for line in r.stderr.splitlines() if line.startswith("fmu_host: early return")]
        early += [float(line.split()[-1]) for line in reported]
    return [[float(x) for x in line.split()] for line in r.stdout.splitlines()]


@pytest.fixture(scope="module")
def runs(hosts, unpacked):
    """run(), each (scenario, platform, FMI version) once for the tests of this module."""
    done = {}

    def get(name, platform, fmi, converged=False):
        if (name, platform, fmi, converged) not in done:
            _, fmus, steps, ops, _ = next(s for s in SCENARIOS if s[0] == name)
            if converged:
                ops = [o for o in ops if not o.startswith("tol:")] + ["tol:1e-10"]
            done[name, platform, fmi, converged] = run(hosts, unpacked, platform, steps, fmus, ops, fmi)
        return done[name, platform, fmi, converged]

    return get


#: Scenarios: (name, FMUs, steps, ops, relative tolerance). Value references are the stable ones
#: of the README (plant: valve.u_ref 0, p1..p4 1-4, Q1..Q4 8-11, cylinder.x 12, v 13, F 14,
#: boom.theta 16, tip deflection 40, boom.flexible 31; controller: u_ref 0, p 1, u 2, u_comp 3,
#: filter.p_lp 10).
PLANT_OUT = [f"print:0:{vr}" for vr in (1, 2, 3, 4, 8, 10, 11, 12, 13, 14)]
SCENARIOS = [
    ("controller, pressure ramp", ["PressureFeedbackController"], 500,
     ["real:0:1=4e6", "ramp:0:1=4e6,2e7", "real:0:0=-0.05", "print:0:2", "print:0:3", "print:0:10"], 1e-12),
    ("HydraulicBoom U, flexible, 2 s", ["HydraulicBoom"], 2000,
     ["real:0:0=-0.05", "tol:1e-6"] + PLANT_OUT + ["print:0:16", "print:0:40"], 5e-5),
    ("HydraulicBoom B with the controller, flexible, 2 s", ["HydraulicBoom", "PressureFeedbackController"], 2000,
     ["real:1:0=-0.05", "link:0:0=1:2", "link:1:1=0:4", "tol:1e-6"] + PLANT_OUT + ["print:1:2", "print:1:3"], 1e-5),
    ("HydraulicCircuit, plain port, lowering at 10 mm/s", ["HydraulicCircuit"], 1000,
     ["real:0:0=-0.05", "real:0:13=-0.01", "ramp:0:12=0.48,-0.01"] + PLANT_OUT[:7] + ["print:0:14"], 1e-5),
    ("BoomMechanics, rigid, held near its start force", ["BoomMechanics"], 1000,
     ["bool:0:31=0", "real:0:14=23000", "print:0:12", "print:0:13", "print:0:16", "print:0:18", "print:0:19"], 1e-5),
]


@pytest.mark.parametrize("ident", IDS)
def test_every_platform_is_in_the_fmu(ident):
    """FMI 2.0 section 2.1: binaries/<platform>/<modelIdentifier>.<so|dll> for each platform, and
    fmpy sees them."""
    with zipfile.ZipFile(fmu_path(ident)) as z:
        names = set(z.namelist())
    for p in PLATFORMS:
        assert f"binaries/{p}/{ident}{SUFFIX[p]}" in names, f"{ident}: no {p} binary (boomsim pack --platforms all)"
    # fmpy 0.3.32 names only the FMI 2.0 platforms (its FMI 2.0 loader on aarch64 looks in linux64).
    assert set(fmpy.supported_platforms(str(fmu_path(ident)))) >= {"linux64", "win64"}
    assert validate_fmu(str(fmu_path(ident))) == []


def exports_and_imports(platform, lib):
    """(exported fmi2/fmi3 symbols, imported libraries) of a binary, read with the platform's binutils."""
    if platform == "win64":
        text = subprocess.run(["x86_64-w64-mingw32-objdump", "-p", str(lib)], capture_output=True, text=True).stdout
        exports = {w for w in text.split() if w.startswith(("fmi2", "fmi3"))}
        imports = {line.split(":")[1].strip().lower() for line in text.splitlines() if "DLL Name:" in line}
        return exports, imports
    prefix = "aarch64-linux-gnu-" if platform == "aarch64-linux" else ""
    nm = subprocess.run([prefix + "nm", "-D", "--defined-only", str(lib)], capture_output=True, text=True).stdout
    exports = {line.split()[-1] for line in nm.splitlines() if line.split()[-1].startswith(("fmi2", "fmi3"))}
    dyn = subprocess.run([prefix + "readelf", "-d", str(lib)], capture_output=True, text=True).stdout
    imports = {line.split("[")[1].rstrip("]") for line in dyn.splitlines() if "(NEEDED)" in line}
    return exports, imports


@pytest.mark.parametrize("ident", IDS)
@pytest.mark.parametrize("platform", PLATFORMS)
def test_exports_and_dependencies(unpacked, ident, platform):
    """fmpy loads all 34 functions: each binary exports exactly the FMI 2.0 and FMI 3.0 functions
    (one library for both versions' .fmu), and imports nothing a plain
    Windows 10 or glibc Linux lacks (no libgcc_s_seh, libwinpthread, libstdc++)."""
    lib = unpacked[2, ident][2][platform]
    exports, imports = exports_and_imports(platform, lib)
    assert exports == EXPORTED
    allowed = ALLOWED_DLLS if platform == "win64" else ALLOWED_SO
    extra = {i for i in imports if i not in allowed and not i.startswith("api-ms-win-core-")}
    assert not extra, f"{ident} on {platform} imports {sorted(extra)}"


@pytest.mark.parametrize("fmi", FMI_VERSIONS)
@pytest.mark.parametrize("name,fmus,steps,ops,rtol", SCENARIOS, ids=[s[0] for s in SCENARIOS])
def test_every_platform_computes_the_same(runs, name, fmus, steps, ops, rtol, fmi):
    """The same scenario on linux64 (native), win64 (wine64) and aarch64-linux (qemu-aarch64),
    through FMI 2.0 and FMI 3.0."""
    reference = runs(name, "linux64", fmi)
    assert len(reference) == steps // 100 and all(len(r) == len(reference[0]) for r in reference)
    # Relative to each output's largest magnitude over the run (a flow crossing zero has no
    # relative error of its own).
    columns = range(len(reference[0]))
    scale = [max(abs(r[j]) for r in reference) or 1.0 for j in columns]
    converged = runs(name, "linux64", fmi, converged=True)
    bound = [max(rtol, 2 * max(abs(a[j] - c[j]) for a, c in zip(reference, converged)) / scale[j]) for j in columns]
    for platform in PLATFORMS[1:]:
        rows = runs(name, platform, fmi)
        assert len(rows) == len(reference)
        excess = [max(abs(a[j] - b[j]) for a, b in zip(reference, rows)) / scale[j] / bound[j] for j in columns]
        j = max(columns, key=lambda j: excess[j])
        print(f"{name} on {platform}, FMI {fmi}: largest relative difference to linux64 "
              f"{excess[j] * bound[j]:.3g} (output {j}, allowed {bound[j]:.3g})")
        assert excess[j] <= 1.0, f"{name} on {platform}, FMI {fmi}: output {j} {excess[j] * bound[j]:.3g} > {bound[j]:.3g}"


@pytest.mark.parametrize("platform", PLATFORMS)
@pytest.mark.parametrize("name", [s[0] for s in SCENARIOS])
def test_fmi3_equals_fmi2_on_the_same_platform(runs, name, platform):
    """FMI 3.0 and FMI 2.0 on one platform: bit for bit (the same library; fmi3DoStep,
    fmi3SetFloat64 ... and their FMI 2.0 counterparts call the same code, and the host passes
    the same values in the same order)."""
    rows2, rows3 = runs(name, platform, 2), runs(name, platform, 3)
    assert len(rows3) == len(rows2) > 0
    differ = [(r2[0], j) for r2, r3 in zip(rows2, rows3) for j, (a, b) in enumerate(zip(r2, r3)) if a != b]
    assert not differ, f"{name} on {platform}: FMI 3.0 differs from FMI 2.0 at (time, column) {differ[:5]}"


def test_the_clocked_controller_on_every_platform(hosts, tmp_path):
    """ClockedPressureFeedbackController (FMI 3.0 only) through the C host's Co-Simulation with
    Event Mode (`clock:0:13`: eventModeUsed, its Clock activated after every 5 ms step) on each
    platform, p ramping by 2e7 Pa/s from 40 bar: at the activations the sampled filter is the high
    pass of the ramp, u_comp = K_f a / Q_rated (1 - e^(-omega_f t)) (eq. 6.2, the defaults of
    Table 7.2): 1e-9 of the plateau (rounding of the filter state over 300 activations), and the
    platforms agree with linux64 to 1e-12 (libm's exp may differ by an ulp)."""
    path = fmu3_path("ClockedPressureFeedbackController")
    with zipfile.ZipFile(path) as z:
        z.extractall(tmp_path)
    token = ET.parse(tmp_path / "modelDescription.xml").getroot().get("instantiationToken")
    libs = {p: tmp_path / "binaries" / TUPLE[p] / ("ClockedPressureFeedbackController" + SUFFIX[p]) for p in PLATFORMS}
    unpacked = {(3, "ClockedPressureFeedbackController"): (tmp_path, token, libs)}
    ops = ["clock:0:13", "real:0:1=4e6", "ramp:0:1=4e6,2e7", "real:0:0=-0.05", "print:0:2", "print:0:3"]
    rows = {p: run(hosts, unpacked, p, 300, ["ClockedPressureFeedbackController"], ops, fmi=3, h="0.005")
            for p in PLATFORMS}
    plateau = 1.24e-11 * 2e7 / (25 / 60000)
    assert [r[0] for r in rows["linux64"]] == pytest.approx([0.5, 1.0, 1.5], abs=1e-12)
    for t, u, u_comp in rows["linux64"]:
        assert u_comp == pytest.approx(plateau * -math.expm1(-35.8 * t), abs=1e-9 * plateau), t
        assert u == -0.05 + u_comp
    flat = {p: [x for row in r for x in row] for p, r in rows.items()}
    for p in PLATFORMS[1:]:
        assert flat[p] == pytest.approx(flat["linux64"], rel=1e-12), p


@pytest.mark.parametrize("platform", PLATFORMS)
def test_intermediate_update_on_every_platform(hosts, unpacked, platform):
    """FMI 3.0 intermediate update through the C host (`intermediate:I:VR`: the callback sets the
    input on its ramp where the FMU requests it, re-entering the library from inside fmi3DoStep) on
    each platform. The controller with p ramping by 2e7 Pa/s from 40 bar takes p linear over each
    1 ms step, so its filter gives the high pass of the ramp exactly, u_comp = K_f a / Q_rated
    (1 - e^(-omega_f t)) (eq. 6.2, Table 7.2's defaults), within 1e-9 of the plateau (rounding);
    with p held over each step instead it is 1.9 % below at 0.1 s. HydraulicBoom with valve.u_ref
    ramping to -0.3 in 1 s by intermediate update runs on each platform as on linux64 (1e-5 of
    each output's range, the bound of the plant scenarios above)."""
    ctrl = ["real:0:1=4e6", "ramp:0:1=4e6,2e7", "real:0:0=-0.05", "print:0:2", "print:0:3"]
    rows = run(hosts, unpacked, platform, 500, ["PressureFeedbackController"], ["intermediate:0:1"] + ctrl, fmi=3)
    held = run(hosts, unpacked, platform, 500, ["PressureFeedbackController"], ctrl, fmi=3)
    plateau = 1.24e-11 * 2e7 / (25 / 60000)
    for (t, _, u_comp), (_, _, u_comp_held) in zip(rows, held):
        exact = plateau * -math.expm1(-35.8 * t)
        assert u_comp == pytest.approx(exact, abs=1e-9 * plateau), t
        assert abs(u_comp_held - exact) > 1e-3 * plateau, t
    plant = ["intermediate:0:0", "real:0:0=0", "ramp:0:0=0,-0.3", "tol:1e-6", "print:0:3", "print:0:4", "print:0:12",
             "print:0:13"]
    rows = run(hosts, unpacked, platform, 1000, ["HydraulicBoom"], plant, fmi=3)
    reference = run(hosts, unpacked, "linux64", 1000, ["HydraulicBoom"], plant, fmi=3)
    for j in range(1, 5):
        scale = max(abs(r[j]) for r in reference)
        assert max(abs(a[j] - b[j]) for a, b in zip(rows, reference)) <= 1e-5 * scale, (platform, j)


@pytest.mark.parametrize("platform", PLATFORMS)
def test_early_return_on_every_platform(hosts, unpacked, platform):
    """FMI 3.0 early return and Event Mode through the C host (`early:0`: eventModeUsed and
    earlyReturnAllowed; after an early return it continues from lastSuccessfulTime, through Event
    Mode where the FMU asks) on each platform: HydraulicBoom, rigid boom, valve.u_ref ramping from
    0.3 through 0 to -0.3 in 0.4 s (held over each 10 ms step): the spool leaves the closed dead
    band lifting, enters it and leaves it lowering: three early returns (FMI 3.0, 4.2.3), at the
    times linux64 finds to 1e-9 s (the platforms' libm differ in the last bit), and the run ends
    where linux64's does (1e-5 of p3, the bound of the plant scenarios above)."""
    ops = ["early:0", "bool:0:31=0", "real:0:0=0.3", "ramp:0:0=0.3,-1.5", "print:0:3"]
    times, reference = [], []
    rows = run(hosts, unpacked, platform, 40, ["HydraulicBoom"], ops, fmi=3, h="0.01", early=times)
    last = run(hosts, unpacked, "linux64", 40, ["HydraulicBoom"], ops, fmi=3, h="0.01", early=reference)
    assert len(reference) == 3, reference
    assert times == pytest.approx(reference, abs=1e-9), platform
    assert rows[-1][1] == pytest.approx(last[-1][1], rel=1e-5)


def test_tools_are_installed():
    """The cross tools of scripts/setup-cross (a missing one fails here with its name)."""
    for tool in ["gcc", "x86_64-w64-mingw32-gcc", "aarch64-linux-gnu-gcc", "qemu-aarch64", WINE]:
        assert shutil.which(tool) or pathlib.Path(tool).exists(), f"{tool} missing: run scripts/setup-cross"
