"""The FMI 3.0 terminals (terminalsAndIcons/terminalsAndIcons.xml, FMI 3.0 section 2.4.9, issue 29
item 3): each file is valid against the standard's schema (fmi3TerminalsAndIcons.xsd as fmpy
ships it), and the SSP packages' connections, now generated from the terminals, are the wiring
docs/coupling.md describes for the monolithic and the split system with either port."""

import pathlib
import zipfile

import fmpy
import pytest
import xmlschema

from boomsim import ssp, terminals
from boomsim.errors import UsageError
from boomsim.scenarios import load_scenario

from conftest import FMU_DIR

MODELS = ["PressureFeedbackController", "HydraulicBoom", "HydraulicCircuit", "BoomMechanics"]
XSD = pathlib.Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3TerminalsAndIcons.xsd"


@pytest.mark.parametrize("model", MODELS)
def test_the_terminals_file_is_valid_against_the_schema(model):
    with zipfile.ZipFile(FMU_DIR / "fmi3" / f"{model}.fmu") as z:
        xml = z.read("terminalsAndIcons/terminalsAndIcons.xml").decode()
    xmlschema.XMLSchema(str(XSD)).validate(xml)


#: The wiring of docs/coupling.md: the fed-back pressure and the valve command, then the port.
FEEDBACK = {("Plant", "p4", "Controller", "p"), ("Controller", "u", "Plant", "valve.u_ref")}
PLAIN = {("Mechanics", "cylinder.x", "Circuit", "cylinder.x"), ("Mechanics", "cylinder.v", "Circuit", "cylinder.v"),
         ("Circuit", "cylinder.F", "Mechanics", "cylinder.F")}
TLM = {("Circuit", "port.c_h", "Mechanics", "port.c_h"), ("Mechanics", "port.c_m", "Circuit", "port.c_m")}


@pytest.mark.parametrize("system,coupling,expected", [
    ("monolithic", "plain", FEEDBACK),
    ("split", "plain", {(a.replace("Plant", "Circuit"), o, b.replace("Plant", "Circuit"), i)
                        for a, o, b, i in FEEDBACK} | PLAIN),
    ("split", "tlm", {(a.replace("Plant", "Circuit"), o, b.replace("Plant", "Circuit"), i)
                      for a, o, b, i in FEEDBACK} | TLM),
])
def test_the_ssp_connections_come_from_the_terminals(system, coupling, expected):
    _, connections = ssp.components(system, load_scenario("B"), "rigid", coupling, 3)
    assert len(connections) == len(expected) and set(connections) == expected


def test_terminals_that_do_not_plug_are_refused_in_one_line():
    with pytest.raises(UsageError, match='PressureFeedbackController has no terminal "rod"'):
        terminals.connect(("Circuit", "HydraulicCircuit"), ("Controller", "PressureFeedbackController"), "rod")
