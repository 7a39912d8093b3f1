"""Project Chrono's vehicle JSON bushings (``"Bushing Data"``), read as a six-axis Kelvin-Voigt set.

Chrono's vehicle templates describe a bushing by four constants in SI units, which its
``ChVehicleBushingData`` applies to the joint's constrained directions: ``"Stiffness Linear"``
[N/m] and ``"Damping Linear"`` [N.s/m] on the three translations, ``"Stiffness Rotational"``
[N.m/rad] and ``"Damping Rotational"`` [N.m.s/rad] on the rotations; and, under ``"DOF"``, the
same four for the joint's free degrees of freedom, of which Chrono (``ChVehicleJoint``'s
bushing) takes the rotational pair only: a revolute joint's rotation about its axis (rz), a
universal joint's two (rx, ry), a spherical joint's three. A suspension file may hold several
bushings, each in the object of the part it mounts (``"Upper Control Arm"``, ``"Lower Control
Arm"``); the file does not say which joint.

Read here (:func:`read_chrono_bushing`): one bushing, chosen by its part's name where the file
holds several, as six Kelvin-Voigt axes in the project's units (x, y, z: k [N/mm] = 1e-3 the
file's, c [N.s/mm] = 1e-3 the file's; rx, ry, rz: k [N.mm/rad] and c [N.mm.s/rad] = 1e3 the
file's); the ``"DOF"`` rotational values go to the free rotations of the joint the caller names
(``revolute``, ``universal``, ``spherical``), and are left out with a warning where none is named
(the linear ones Chrono never takes). Chrono reads its JSON with comments allowed: ``//`` and
``/* */`` comments are skipped here too. A key the reader does not know is named in a warning; a
missing constant, a value that is not a finite number, a negative stiffness or damping, a name
that is not among the file's bushings are errors naming the file, the key and what is allowed.
"""
from __future__ import annotations

import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

from fmu_src.model.registry import LINEAR_BASELINE
from identification.errors import IdentificationError

FORMAT = "chrono-json"
BUSHING_KEY = "Bushing Data"
CONSTANTS = {"Stiffness Linear": ("N/m", 1e-3), "Damping Linear": ("N.s/m", 1e-3),
             "Stiffness Rotational": ("N.m/rad", 1e3), "Damping Rotational": ("N.m.s/rad", 1e3)}
"""Each constant Chrono's bushing data holds: its unit in the file and the factor to the project's
(N/mm, N.s/mm on translations; N.mm/rad, N.mm.s/rad on rotations)."""
TRANSLATIONS, ROTATIONS = ("x", "y", "z"), ("rx", "ry", "rz")
FREE_ROTATIONS = {"revolute": ("rz",), "universal": ("rx", "ry"), "spherical": ("rx", "ry", "rz")}
"""The rotations each joint leaves free, which take a Chrono bushing's DOF values (about the joint's
frame: a revolute joint turns about its z axis)."""


class PropertyFileWarning(UserWarning):
    """Something a property file holds that its reader does not take (named, never dropped silently)."""


@dataclass(frozen=True)
class ImportedBushing:
    """A bushing read from another tool's file: ``axes`` {axis: (model, parameters in the
    project's units)} as ``parameter_files.save_six_axis`` takes them, and its ``provenance``
    (the file, the bushing's name, the format, the free axis)."""
    axes: dict
    provenance: dict


def bushings_in(document, path: Path) -> dict[str, dict]:
    """{part name: its bushing data} of every ``"Bushing Data"`` object in the document, at any
    depth (the part's name is the key of the object that holds it)."""
    found: dict[str, dict] = {}

    where: dict[str, str] = {}

    def visit(node, name: str, trail: str) -> None:
        if isinstance(node, dict):
            for key, value in node.items():
                if key == BUSHING_KEY:
                    if not isinstance(value, dict):
                        raise IdentificationError(f"{path}: {name!r}: {BUSHING_KEY!r} is not an object")
                    if name in found:
                        raise IdentificationError(f"{path}: two bushings are named {name!r} ({where[name]} and "
                                                  f"{trail}): rename one")
                    found[name], where[name] = value, trail
                else:
                    visit(value, key, f"{trail}/{key}")
        elif isinstance(node, list):
            for i, item in enumerate(node):
                visit(item, name, f"{trail}[{i}]")
    visit(document, "", "")
    return found


def _constants(data: dict, path: Path, where: str) -> dict[str, float]:
    """The four constants of ``data`` in the file's units, checked."""
    values = {}
    for key, (unit, _) in CONSTANTS.items():
        if key not in data:
            raise IdentificationError(f"{path}: {where}: missing {key!r} [{unit}]; a Chrono bushing gives "
                                      f"{', '.join(CONSTANTS)}")
        value = data[key]
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
            raise IdentificationError(f"{path}: {where}: {key} = {value!r} is not a finite number [{unit}]")
        if value < 0:
            raise IdentificationError(f"{path}: {where}: {key} = {value!r} [{unit}] must be >= 0 (a negative "
                                      f"{'spring is unstable' if 'Stiffness' in key else 'dashpot adds energy'})")
        values[key] = float(value)
    return values


def without_comments(text: str) -> str:
    """JSON text without ``//`` and ``/* */`` comments (outside strings), each comment's line breaks
    kept so that a parse error's line is the file's."""
    out, i, string = [], 0, False
    while i < len(text):
        c = text[i]
        if string:
            out.append(c)
            if c == "\\":
                out.append(text[i + 1:i + 2])
                i += 1
            elif c == '"':
                string = False
        elif c == '"':
            string = True
            out.append(c)
        elif text.startswith("//", i):
            end = text.find("\n", i)
            i = len(text) if end < 0 else end
            continue
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = len(text) if end < 0 else end + 2
            out.append("\n" * text.count("\n", i, end))
            i = end
            continue
        else:
            out.append(c)
        i += 1
    return "".join(out)


def read_chrono_bushing(path: str | Path, bushing: str | None = None, joint: str | None = None) -> ImportedBushing:
    """The bushing ``bushing`` (its part's name; may be left out where the file holds one) of the
    Chrono vehicle JSON file ``path`` as a six-axis Kelvin-Voigt set (module docstring).
    ``joint`` (revolute, universal, spherical): the joint the bushing replaces, whose free
    rotations take the file's ``"DOF"`` values; None: they are left out with a warning."""
    path = Path(path)
    try:
        document = json.loads(without_comments(path.read_text(encoding="utf-8-sig")))
    except FileNotFoundError:
        raise IdentificationError(f"Chrono JSON file {path} does not exist") from None
    except UnicodeDecodeError as exc:
        raise IdentificationError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise IdentificationError(f"{path}, line {exc.lineno}, column {exc.colno}: not JSON ({exc.msg})") from None
    found = bushings_in(document, path)
    if not found:
        raise IdentificationError(f"{path}: no {BUSHING_KEY!r} object: not a Chrono vehicle file with a bushing")
    if bushing is None:
        if len(found) > 1:
            raise IdentificationError(f"{path} holds {len(found)} bushings: name one with --bushing (one of "
                                      f"{', '.join(repr(name) for name in found)})")
        bushing = next(iter(found))
    if bushing not in found:
        raise IdentificationError(f"{path}: no bushing {bushing!r}; the file's are "
                                  f"{', '.join(repr(name) for name in found)}")
    if joint is not None and joint not in FREE_ROTATIONS:
        raise IdentificationError(f"joint {joint!r}: one of {', '.join(FREE_ROTATIONS)}")
    data = found[bushing]
    where = f"{bushing!r}"
    unknown = sorted(set(data) - set(CONSTANTS) - {"DOF"})
    if unknown:
        warnings.warn(f"{path}: {where}: {', '.join(repr(k) for k in unknown)} not read (a Chrono bushing's "
                      f"constants are {', '.join(CONSTANTS)} and DOF)", PropertyFileWarning, stacklevel=2)
    constrained = _constants(data, path, where)
    free = None
    if "DOF" in data:
        if not isinstance(data["DOF"], dict):
            raise IdentificationError(f"{path}: {where}: 'DOF' is not an object")
        unknown = sorted(set(data["DOF"]) - set(CONSTANTS))
        if unknown:
            warnings.warn(f"{path}: {where}, DOF: {', '.join(repr(k) for k in unknown)} not read",
                          PropertyFileWarning, stacklevel=2)
        free = _constants(data["DOF"], path, f"{where}, DOF")
        if joint is None:
            warnings.warn(f"{path}: {where}: its DOF values ({', '.join(f'{k} {v:g}' for k, v in free.items())}) "
                          "belong to the free rotations of the joint it replaces, which the file does not name: "
                          "left out (every axis takes the constrained values); name the joint (--joint revolute, "
                          "universal or spherical) to take them", PropertyFileWarning, stacklevel=2)
    elif joint is not None:
        raise IdentificationError(f"{path}: {where} has no 'DOF' values for the {joint} joint's free rotations")
    free_axes = FREE_ROTATIONS.get(joint, ()) if free is not None else ()
    axes = {}
    for axis in TRANSLATIONS + ROTATIONS:
        kind = "Linear" if axis in TRANSLATIONS else "Rotational"
        source = free if axis in free_axes else constrained
        axes[axis] = (LINEAR_BASELINE.name, {"k": source[f"Stiffness {kind}"] * CONSTANTS[f"Stiffness {kind}"][1],
                                       "c": source[f"Damping {kind}"] * CONSTANTS[f"Damping {kind}"][1],
                                       "preload": 0.0})
    provenance = {"imported_from": str(path), "format": FORMAT, "bushing": bushing,
                  "joint": joint, "free_axes": list(free_axes), "units_converted": {k: f"{u} x {f:g}" for k, (u, f) in CONSTANTS.items()}}
    return ImportedBushing(axes, provenance)
