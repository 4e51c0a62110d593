"""Issue 50: every bad input to boomsim.run (both interfaces) is a UsageError that names the
argument, the value and what is allowed, raised before any FMU instance exists; a Result too short
for the metrics says so. One case per row of the issue's table, and the ranges come from the
modelDescription (boom.xi: [0, 1]; K_f: [0, 1e-8])."""

import pytest

import boomsim
from boomsim import UsageError

CASES = [
    ({"boom": "bendy"}, "boom='bendy': \"rigid\" or \"flexible\""),
    ({"feedback_start": "later"}, "feedback_start='later': \"t0\""),
    ({"stop_time": 0.0105}, "stop_time=0.0105: a whole multiple of the step 0.001 s"),
    ({"params": {"pcv.nope": 1.0}}, "params['pcv.nope']: no such variable of HydraulicBoom or PressureFeedbackController"),
    ({"params": {"p3": 1.0}}, "params['p3']: a variable that is not a parameter"),
    ({"params": {"boom.xi": 5.0}}, "params['boom.xi'] = 5.0 is outside its valid range [0, 1]"),
    ({"params": {"K_f": -1.0}}, "params['K_f'] = -1.0 is outside its valid range [0, 1e-8]"),
    ({"params": {"boom.n2": 2.5}}, "params['boom.n2'] = 2.5: a whole number"),
    ({"params": {"boom.xi": "abc"}}, "params['boom.xi'] = 'abc': a finite number"),
    ({"params": {"boom.damping": "viscous"}},
     "params['boom.damping'] = 'viscous' is no item of DampingLaw: 'thesis' (0), 'structural' (1), 'modal' (2), "
     "'converged_modal' (3)"),
    ({"params": {"friction.model": 3}}, "params['friction.model'] = 3 is no item of FrictionModel"),
    ({"step": -1e-3}, "step=-0.001: a finite number > 0 [s]"),
    ({"step": 0.0}, "step=0.0: a finite number > 0 [s]"),
    ({"stop_time": -1.0}, "stop_time=-1.0: a finite number > 0 [s]"),
    ({"tolerance": -1.0}, "tolerance=-1.0: a finite number > 0"),
]


@pytest.mark.parametrize("interface", ["cs", "me"])
@pytest.mark.parametrize("kwargs, message", CASES)
def test_bad_input_is_a_usage_error(monkeypatch, interface, kwargs, message):
    """The message names the argument and the rule, and no FMU was instantiated (FmuFile.slave and
    .model are never reached). Model Exchange has no step: its step rows are the step's own error."""
    from boomsim.fmus import FmuFile

    if interface == "me" and "step" in kwargs:
        message = "Model Exchange has no communication step"
    if interface == "me" and "stop_time" in kwargs and kwargs["stop_time"] == 0.0105:
        pytest.skip("Model Exchange records every millisecond of any stop time")

    def refuse(*_args, **_kwargs):
        raise AssertionError("an FMU was instantiated for bad input")

    monkeypatch.setattr(FmuFile, "slave", refuse)
    monkeypatch.setattr(FmuFile, "model", refuse)
    with pytest.raises(UsageError) as e:
        boomsim.run("B", **{"stop_time": 0.02, "interface": interface, **kwargs})
    assert message in str(e.value)


def test_metrics_of_a_short_run_say_how_long_is_needed():
    """The metrics take p3's peak-to-peak in 1 s windows: a 0.5 s record is a UsageError that says
    so, and a 1 s record has them."""
    with pytest.raises(UsageError, match="metrics of a 0.5 s record: they need at least 1 s"):
        boomsim.run("B", stop_time=0.5).metrics
    assert boomsim.run("B", stop_time=1.0).metrics["p3_pp_max"] > 0


def enumeration_table() -> dict:
    """docs/fmus.md's table of Enumerations: {parameter: (type, [items], default)}."""
    import pathlib

    text = (pathlib.Path(__file__).resolve().parents[2] / "docs" / "fmus.md").read_text()
    rows = text.split("## Laws: Enumerations", 1)[1].split("\n\n")[2].splitlines()[2:]
    cells = [[c.strip().strip("`") for c in r.strip("|").split("|")] for r in rows]
    return {name: (ty, items.split(", "), default) for name, ty, items, default in cells}


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_docs_enumerations_are_the_fmus(fmi):
    """docs/fmus.md's table against each FMU's modelDescription (FMI 2.0, 2.2.3 / FMI 3.0, 2.4.6):
    the declared type, its items in the order of their values 0, 1, ... (the docs' rule), the
    start value's item; and no Enumeration the table leaves out."""
    from boomsim.fmus import FmuFile

    table = enumeration_table()
    seen = set()
    for model in ("HydraulicBoom", "HydraulicCircuit", "BoomMechanics"):
        for v in FmuFile.get(model, fmi).vars.values():
            if v.type != "Enumeration":
                continue
            ty, items, default = table[v.name]
            assert v.declaredType.name == ty
            assert [(i.name, int(i.value)) for i in v.declaredType.items] == [(n, k) for k, n in enumerate(items)]
            assert items[int(v.start)] == default, v.name
            seen.add(v.name)
    assert seen == set(table)


@pytest.mark.parametrize("fmi", [2, 3])
def test_an_enumeration_is_set_by_its_items_name(fmi):
    """FmuFile.set writes an item's name as its value: fmi2SetInteger in FMI 2.0, fmi3SetInt64 in
    FMI 3.0 (2.4.7.4), read back by the same version's getter; the value itself is taken too."""
    from boomsim.fmus import FmuFile

    f = FmuFile.get("HydraulicBoom", fmi)
    s = f.slave("enumeration")
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    r = f.vr["boom.damping"]
    get = s.getInt64 if fmi == 3 else s.getInteger
    for value, expected in (("thesis", 0), ("converged_modal", 3), (1, 1)):
        f.set(s, "boom.damping", value)
        assert list(get([r])) == [expected]
    s.freeInstance()  # from Initialization Mode (FMI 2.0, 4.3.1: fmi2Terminate is not allowed there)
