"""The numbers of docs/ that restate what the code computes, checked against the code (issue 50,
"Numbers that contradict each other"): the plant's modes against `boomsim eigen --json` (about a
second per call), and the one-source rule for the benchmark figures, which are measured once (a
command, a machine, a date) and linked elsewhere, not restated.

Tolerances: a doc rounds, so a stated figure must equal the computed one rounded to the digits
the doc gives (half a unit of its last digit, plus 1e-9 relative for the binary value); the
linearisation's own error (about 1e-5 relative, `tools/src/analysis/modes.rs`) is far below the
digits stated."""

import json
import re
import subprocess
from decimal import Decimal

import pytest

from conftest import ROOT

BOOMSIM = ROOT / "target" / "release" / "boomsim"
DOCS = ROOT / "docs"


def page(name: str) -> str:
    """docs/<name> with its whitespace runs made single spaces (line breaks fall anywhere)."""
    return " ".join((DOCS / name).read_text().split())


def eigen(*args: str) -> dict:
    if not BOOMSIM.exists():
        pytest.skip(f"{BOOMSIM} is missing: cargo build --release")
    out = subprocess.run([str(BOOMSIM), "eigen", "--json", "--count", "12", *args],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.fixture(scope="module")
def thesis() -> dict:
    return eigen("--set", "boom.damping=thesis")


@pytest.fixture(scope="module")
def modal() -> dict:
    return eigen()


def rounds_to(stated: str, value: float) -> bool:
    """`stated` ("47.5", "4") is `value` rounded to the digits `stated` gives."""
    half = Decimal(1).scaleb(Decimal(stated).as_tuple().exponent) / 2
    return abs(value - float(stated)) <= float(half) * (1 + 1e-9) + 1e-9 * abs(value)


def check(stated: str, value: float, what: str):
    assert rounds_to(stated, value), f"{what}: the docs say {stated}, boomsim eigen gives {value:.6g}"


def test_coupling_lists_the_arms_modes_under_both_laws(thesis, modal):
    """docs/coupling.md's opening, the one list of the arm's modes: under the thesis' law the
    five above the lowest with their damping range, under the modal law the first of them and the
    range of the next four."""
    text = page("coupling.md")
    m = re.search(r"the flexible arm adds modes at ([\d., and]+) Hz with damping ratios of "
                  r"([\d.]+)-([\d.]+) % under the thesis' damping law", text)
    assert m, "docs/coupling.md: the list of the arm's modes under the thesis' law"
    stated = re.split(r",\s*|\s+and\s+", m.group(1).strip())
    modes = thesis["modes"][1:1 + len(stated)]
    assert len(stated) == 5 and len(modes) == 5, stated
    for s, mode in zip(stated, modes):
        check(s, mode["frequency_hz"], "thesis' law, frequency")
    zetas = [100 * mode["damping_ratio"] for mode in modes]
    check(m.group(2), min(zetas), "thesis' law, least damping [%]")
    check(m.group(3), max(zetas), "thesis' law, most damping [%]")

    m = re.search(r"under the default modal law the first of them is at ([\d.]+) Hz with ([\d.]+) % "
                  r"damping and the others at ([\d.]+)-([\d.]+) Hz with ([\d.]+)-([\d.]+) %", text)
    assert m, "docs/coupling.md: the arm's modes under the modal law"
    first, others = modal["modes"][1], modal["modes"][2:6]
    check(m.group(1), first["frequency_hz"], "modal law, first frequency")
    check(m.group(2), 100 * first["damping_ratio"], "modal law, first damping [%]")
    check(m.group(3), min(o["frequency_hz"] for o in others), "modal law, others' lowest")
    check(m.group(4), max(o["frequency_hz"] for o in others), "modal law, others' highest")
    check(m.group(5), min(100 * o["damping_ratio"] for o in others), "modal law, others' least damping")
    check(m.group(6), max(100 * o["damping_ratio"] for o in others), "modal law, others' most damping")

    # The plain coupling's bound derived from them: h < 4 zeta / omega over those modes.
    m = re.search(r"need h < 4 zeta / omega ~ ([\d.]+) ms", text)
    assert m, "docs/coupling.md: the plain coupling's bound for the thesis' law"
    bound = min(4 * mode["damping_ratio"] / (2 * 3.141592653589793 * mode["frequency_hz"]) for mode in modes)
    check(m.group(1), bound * 1e3, "h bound [ms]")


def test_every_page_names_the_modes_as_eigen_gives_them(thesis, modal):
    """Each page that names a mode by its frequency: "47.5 Hz" is the thesis' law's second mode,
    "55.5 Hz" the modal law's, "3.6 Hz" the rigid boom's mode, "2.5 Hz mode" the flexible plant's
    lowest (2.48 Hz at 0 bar, 2.54 Hz at the rig's 1 bar: both round to it)."""
    named = {
        "47.5 Hz": thesis["modes"][1]["frequency_hz"],
        "55.5 Hz": modal["modes"][1]["frequency_hz"],
        "3.6 Hz": thesis["rigid_modes"][0]["frequency_hz"],
        "2.5 Hz mode": modal["modes"][0]["frequency_hz"],
    }
    seen = set()
    for doc in sorted(DOCS.glob("*.md")) + [ROOT / "README.md"]:
        text = " ".join(doc.read_text().split())
        for name, value in named.items():
            if name in text:
                seen.add(name)
                check(name.split()[0], value, f"{doc.name}: {name}")
        # No other figure for the same modes: "NN Hz" with a damping of the thesis' second mode
        # written differently (the "48-283 Hz" and "47-729 Hz").
        for stale in ("48-283 Hz", "47-729 Hz", "0.2-1.2 %"):
            assert stale not in text, f"{doc.name}: {stale} (coupling.md lists the modes)"
    assert seen == set(named), f"not found in docs: {set(named) - seen}"
    # The rigid mode as an angular frequency in docs/coupling.md's stability bound.
    m = re.search(r"Rigid boom \(kappa = 1, omega = ([\d.]+) rad/s\)", page("coupling.md"))
    assert m, "docs/coupling.md: the rigid boom's omega"
    check(m.group(1), 2 * 3.141592653589793 * named["3.6 Hz"], "coupling.md: omega [rad/s]")
    # Any "N Hz mode" of any page is one of the modes eigen computes (either law, rigid, the rig's).
    computed = [m["frequency_hz"] for d in (thesis, modal) for m in d["modes"] + d["rigid_modes"]]
    computed += [modal["rig"]["frequency_hz"], modal["rig"]["rigid_frequency_hz"]]
    for doc in sorted(DOCS.glob("*.md")) + [ROOT / "README.md"]:
        for stated in re.findall(r"(\d+(?:\.\d+)?) Hz mode", " ".join(doc.read_text().split())):
            assert any(rounds_to(stated, f) for f in computed), f"{doc.name}: a {stated} Hz mode, eigen has none"
    # The modal law's second mode and its damping where the model notes explain the law.
    notes = page("models.md")
    m = re.search(r"47\.5 Hz mode with ([\d.]+) % damping under the thesis' law, and the modal law "
                  r"damps it too \(([\d.]+) Hz, ([\d.]+) %", notes)
    assert m, "docs/models.md: the modal law's effect on the 47.5 Hz mode"
    check(m.group(1), 100 * thesis["modes"][1]["damping_ratio"], "models.md: thesis' damping [%]")
    check(m.group(2), modal["modes"][1]["frequency_hz"], "models.md: modal frequency")
    check(m.group(3), 100 * modal["modes"][1]["damping_ratio"], "models.md: modal damping [%]")


def test_the_lowest_mode_at_either_rod_side_pressure(modal):
    """docs/coupling.md gives the flexible plant's lowest mode at the rod side's 0 bar (`boomsim
    eigen`'s default) and at the rig's trapped 1 bar (its `rig` entry), saying which is which."""
    text = page("coupling.md")
    m = re.search(r"the lowest mode \(([\d.]+) Hz, `boomsim eigen` with the rod side at 0 bar; "
                  r"([\d.]+) Hz at the rig's trapped 1 bar", text)
    assert m, "docs/coupling.md: the flexible arm's lowest mode"
    assert modal["p4_bar"] == 0.0 and modal["rig"]["p4_bar"] == 1.0
    check(m.group(1), modal["modes"][0]["frequency_hz"], "lowest mode at 0 bar")
    check(m.group(2), modal["rig"]["frequency_hz"], "lowest mode at 1 bar")


#: Benchmark figures measured once, on one page (the command, machine and date stated there),
#: and linked from the others: each may appear on its own page only. They are wall-time figures,
#: not re-run by a test (`boomsim bench` takes minutes on 2 cores and varies with load); the
#: counts beside them are exact.
ONE_PLACE = {
    # U rigid, in-process real-time factor: docs/performance.md's table.
    "357-361x": "performance.md",
    # U flexible under the thesis' law: a ratio, on the damping table only.
    "3.5-3.6x faster": "performance.md",
    # Model Exchange wall times: docs/interfaces.md's "Which to choose" table.
    "| 3.79 |": "interfaces.md",
}
#: Figures of older measurements that contradicted those (issue 50): gone.
GONE = ["346-349x", "32-33x", "33x -> 121-122x", "34x -> 120-123x", "wall 3.7 s", "to 814 RHS",
        "1 667 to 814", "70 Hz to 10 kHz"]


def test_benchmark_figures_have_one_source():
    docs = {d.name: " ".join(d.read_text().split()) for d in sorted(DOCS.glob("*.md"))}
    docs["README.md"] = " ".join((ROOT / "README.md").read_text().split())
    for figure, home in ONE_PLACE.items():
        where = sorted(name for name, text in docs.items() if figure in text)
        assert where == [home], f"{figure}: on {where}, its one place is docs/{home}"
    for figure in GONE:
        where = sorted(name for name, text in docs.items() if figure in text)
        assert not where, f"{figure} (a superseded figure, issue 50) on {where}"
    # The measurements say when, where and with what.
    perf, interfaces = docs["performance.md"], docs["interfaces.md"]
    assert "`target/release/boomsim bench`, measured on 2026-12-05" in perf
    assert "Measured on 2026-12-05 at dc585f1" in interfaces and "scripts/bench_interfaces.py" in interfaces


def test_the_damping_tables_model_exchange_counts_are_the_interface_tables():
    """docs/performance.md's damping table gives the default law's Model Exchange RHS counts to form
    its ratios; they are the same runs as docs/interfaces.md's table (scripts/bench_interfaces.py),
    so they must agree exactly, and the ratios must be the counts' (to the digits stated)."""
    interfaces = (DOCS / "interfaces.md").read_text()
    me = {}
    for line in interfaces.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 8 and cells[2] == "ME CVode" and cells[1].startswith("flexible"):
            me[cells[0]] = int(cells[5])
    assert set(me) == {"U", "B"}, me
    perf = (DOCS / "performance.md").read_text()
    for case in ("U", "B"):
        row = next(line for line in perf.splitlines() if line.startswith(f"| {case} flexible | ME, fmpy CVode"))
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        thesis, modal, ratio = int(cells[2].replace(" ", "")), int(cells[4].replace(" ", "")), cells[5]
        assert modal == me[case], f"{case} flexible ME: {modal} RHS on performance.md, {me[case]} on interfaces.md"
        assert rounds_to(ratio, thesis / modal), f"{case}: {ratio} against {thesis / modal:.4g}"


def test_the_test_commands_duration_is_the_changelogs_range():
    """README.md and docs/development.md give `scripts/test`'s duration as the range of the quiet
    fresh-clone runs that CHANGELOG.md tables, rounded to whole minutes."""
    quiet = []
    for line in (ROOT / "CHANGELOG.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 7 and cells[3] == "quiet":
            quiet.append(float(cells[4]))
    assert len(quiet) >= 2, "CHANGELOG.md's table of test command durations has no quiet runs"
    stated = f"`scripts/test` {round(min(quiet))} to {round(max(quiet))} minutes from a fresh clone"
    for page in (ROOT / "README.md", DOCS / "development.md"):
        assert stated in " ".join(page.read_text().split()), f"{page.name} should say: {stated}"


def test_the_cylinders_domain_is_its_dead_volumes():
    """docs/models.md's end-stop paragraph: BoomMechanics' stroke domain ends where a chamber's
    dead volume is gone, V_dead / area past a stop (areas of the bore and the annulus from the
    diameters), computed here from HydraulicBoom's parameters (the same cylinder), to the digits
    stated, and the force the stops take there, k_stop times the piston side's distance."""
    import math
    import xml.etree.ElementTree as ET

    root = ET.parse(ROOT / "modelDescription" / "HydraulicBoom.xml").getroot()
    p = {v.get("name"): float(v[0].get("start")) for v in root.iter("ScalarVariable")
         if v.get("name", "").startswith("cylinder.") and v.get("causality") == "parameter"}
    a = math.pi / 4 * p["cylinder.d_piston"] ** 2
    a_rod_side = math.pi / 4 * (p["cylinder.d_piston"] ** 2 - p["cylinder.d_rod"] ** 2)
    below, above = p["cylinder.v_dead_a"] / a * 1e3, p["cylinder.v_dead_b"] / a_rod_side * 1e3
    text = page("models.md")
    stated = re.search(r"\(([\d.]+) mm at the piston side, ([\d.]+) mm at the rod side\)", text)
    domain = re.search(r"the stroke from -([\d.]+) to ([\d.]+) mm", text)
    force = re.search(r"the stops take up to ([\d.]+) MN", text)
    assert stated and domain and force, "models.md's end-stop paragraph changed its wording"
    check(stated[1], below, "piston side")
    check(stated[2], above, "rod side")
    check(domain[1], below, "domain's lower end")
    check(domain[2], p["cylinder.stroke"] * 1e3 + above, "domain's upper end")
    check(force[1], p["cylinder.k_stop"] * below * 1e-3 / 1e6, "the stops' force there")
    conformance = re.search(r"the stroke outside \[-([\d.]+), ([\d.]+)\] mm", page("conformance.md"))
    assert conformance, "conformance.md's domain sentence changed its wording"
    check(conformance[1], below, "conformance.md's lower end")
    check(conformance[2], p["cylinder.stroke"] * 1e3 + above, "conformance.md's upper end")


def test_python_md_names_pyprojects_lower_bounds():
    """docs/python.md lists the oldest versions the package's tests pass on: each is the lower
    bound pyproject.toml declares (scripts/oldest-deps installs those), and every bound is listed."""
    import tomllib

    project = tomllib.loads((ROOT / "python" / "pyproject.toml").read_text())["project"]
    declared = [*project["dependencies"], *(d for extra in ("sweeps", "pandas") for d in project["optional-dependencies"][extra])]
    bounds = {m[1].lower(): m[2] for d in declared if (m := re.match(r"([A-Za-z_-]+)>=([\d.]+)", d))}
    text = page("python.md")
    listed = re.search(r"pass \((.*?)\), which `bash scripts/oldest-deps`", text)
    assert listed, "docs/python.md's sentence on the lower bounds changed its wording"
    stated = {}
    for names, version in re.findall(r"([a-z][a-z, ]*?) ([\d.]+\d)", listed[1].replace(" and ", ", ")):
        for name in names.split(","):
            name = name.strip().split()[-1] if name.strip() else ""
            if name:
                stated[name] = version
    assert stated == bounds, f"docs/python.md: {stated}; pyproject.toml: {bounds}"
