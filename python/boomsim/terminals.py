"""The FMUs' terminals (terminalsAndIcons/terminalsAndIcons.xml of the FMI 3.0 .fmu files, FMI 3.0
section 2.4.9) and the connections they define: two components' terminals of the same name and
`terminalKind` connect member by member (`matchingRule="plug"`), each output member to the input
member of the same `memberName`; a parameter member (the TLM line's Z_c) is not a connection but a
value both sides must share."""

from __future__ import annotations

import xml.etree.ElementTree as ET
import zipfile

from .errors import UsageError
from .fmus import FmuFile


def terminals(model: str) -> dict[str, tuple[str, dict[str, str]]]:
    """{terminal name: (terminalKind, {memberName: variable name})} of `model` (its FMI 3.0 .fmu;
    the variable names are the same in FMI 2.0)."""
    with zipfile.ZipFile(FmuFile.get(model, 3).path) as z:
        root = ET.fromstring(z.read("terminalsAndIcons/terminalsAndIcons.xml"))
    return {t.get("name"): (t.get("terminalKind"), {m.get("memberName"): m.get("variableName")
                                                    for m in t.findall("TerminalMemberVariable")})
            for t in root.iter("Terminal")}


def connect(a: tuple[str, str], b: tuple[str, str], name: str) -> tuple[list, list]:
    """The connections of terminal `name` between components a and b, each (component name, FMU
    id): ([(from component, output, to component, input)], [(a's parameter, b's parameter)]) in
    the order of a's members; a UsageError when the terminals do not match under `plug`."""
    (ca, ma), (cb, mb) = a, b
    ta, tb = terminals(ma), terminals(mb)
    for model, found in ((ma, ta), (mb, tb)):
        if name not in found:
            raise UsageError(f"{model} has no terminal \"{name}\": it has {', '.join(found)}")
    (kind_a, members_a), (kind_b, members_b) = ta[name], tb[name]
    if kind_a != kind_b or set(members_a) != set(members_b):
        raise UsageError(f"terminal \"{name}\": {ma}'s ({kind_a}: {sorted(members_a)}) does not plug into "
                         f"{mb}'s ({kind_b}: {sorted(members_b)})")
    causality = {c: FmuFile.get(m).vars for c, m in (a, b)}
    connections, parameters = [], []
    for member, va in members_a.items():
        vb = members_b[member]
        kinds = (causality[ca][va].causality, causality[cb][vb].causality)
        if kinds == ("output", "input"):
            connections.append((ca, va, cb, vb))
        elif kinds == ("input", "output"):
            connections.append((cb, vb, ca, va))
        elif kinds == ("parameter", "parameter"):
            parameters.append((va, vb))
        else:
            raise UsageError(f"terminal \"{name}\", member {member}: {ma}.{va} is an {kinds[0]}, "
                             f"{mb}.{vb} an {kinds[1]}")
    return connections, parameters
