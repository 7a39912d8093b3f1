"""Altair's bushing property files (``.gbs``, the General Bushing System's), read as a six-axis set.

The layout its documentation gives, in the TeimOrbit format (``teimorbit``): ``[HEADER]``,
``[UNITS]`` (``LENGTH``, ``ANGLE``, ``FORCE``, ``MASS``, ``TIME``), ``[GLOBAL]``, ``[DIRECTIONS]``
with an ``(ACTIVITY)`` table ``{ formulation FX FY FZ TX TY TZ }`` (a 1 where a formulation is
active in a direction; the direction's force is the sum of its active ones), ``[FRICTION]``, and
per direction its formulations' blocks: ``[SPLINE_STIFFNESS_FX]`` (a ``(SPLINE_DATA)`` table
``{ disp force }``, deflection increasing), ``[CONSTANT_STIFFNESS_FX]`` (``K``),
``[CUBIC_STIFFNESS_FX]``, ``[CONSTANT_DAMPING_FX]`` (``C``), ``[RUBBER_DAMPING_FX]``,
``[HYDROMOUNT_DAMPING_FX]``. Installation data (offset, preload, scale) are the solver model's,
not the file's.

Read here (:func:`read_gbs`), per direction (FX, FY, FZ on x, y, z; TX, TY, TZ on rx, ry, rz), in
the project's units (mm, rad, N, N.mm, s):

- a spline stiffness: the ``backbone<K>`` option on Kelvin-Voigt, its knots the spline's points
  (K <= 32): the static force at every knot the file's, the monotone cubic between them (Altair's
  own interpolation between the points may differ there);
- a constant stiffness: Kelvin-Voigt's ``k``; with a spline in the same direction it is refused
  (the sum of a spline and a line is a spline the file could have given);
- a constant damping: Kelvin-Voigt's ``c`` (0 where none is active);
- a cubic stiffness, a rubber or hydromount damping, friction: read, named in a warning with their
  values, and left out (no model of the project says them the same way yet);
- a direction with no formulation active: a free axis (k = 0, c = 0), warned.

Refused, with the file, the line and what is allowed: a unit the reader does not know, a spline
whose deflection does not increase or whose table is not ``{ disp force }`` of numbers, a
direction the activity table leaves out, an active formulation without its block, a block the
layout does not know, a value given twice in a block.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

from fmu_src.model.registry import LINEAR_BASELINE
from identification.errors import IdentificationError
from identification.property_files.chrono_json import ImportedBushing, PropertyFileWarning
from identification.property_files.teimorbit import read_layout

FORMAT = "gbs"
DIRECTIONS = {"FX": "x", "FY": "y", "FZ": "z", "TX": "rx", "TY": "ry", "TZ": "rz"}
FORMULATIONS = ("SPLINE_STIFFNESS", "CONSTANT_STIFFNESS", "CUBIC_STIFFNESS", "CONSTANT_DAMPING", "RUBBER_DAMPING",
                "HYDROMOUNT_DAMPING")
LENGTH_MM = {"mm": 1.0, "millimeter": 1.0, "millimetre": 1.0, "cm": 10.0, "centimeter": 10.0, "m": 1000.0,
             "meter": 1000.0, "metre": 1000.0, "inch": 25.4, "in": 25.4, "foot": 304.8, "ft": 304.8}
ANGLE_RAD = {"rad": 1.0, "radian": 1.0, "radians": 1.0, "deg": math.pi / 180.0, "degree": math.pi / 180.0,
             "degrees": math.pi / 180.0}
FORCE_N = {"newton": 1.0, "n": 1.0, "kilonewton": 1000.0, "kn": 1000.0, "pound_force": 4.4482216152605,
           "lbf": 4.4482216152605, "kg_force": 9.80665, "kgf": 9.80665, "kilogram_force": 9.80665}
TIME_S = {"second": 1.0, "sec": 1.0, "s": 1.0, "millisecond": 1e-3, "ms": 1e-3, "minute": 60.0, "hour": 3600.0}
KNOWN_BLOCKS = {"HEADER", "UNITS", "GLOBAL", "DIRECTIONS", "FRICTION"} | {
    f"{formulation}_{direction}" for formulation in FORMULATIONS for direction in DIRECTIONS}
MAX_KNOTS = 32


def _unit(blocks, path: Path, name: str, table: dict, default: str | None = None) -> float:
    units = blocks.get("UNITS")
    if units is None or name not in units.values:
        if default is not None:
            return table[default]
        raise IdentificationError(f"{path}: [UNITS] gives no {name}; allowed: {', '.join(table)}")
    line, value = units.values[name]
    key = str(value).strip().lower()
    if key not in table:
        raise IdentificationError(f"{path}, line {line}: {name} = {value!r} is not a unit this reader knows; "
                                  f"allowed: {', '.join(table)}")
    return table[key]


def _activity(blocks, path: Path) -> dict[str, set[str]]:
    """{direction: its active formulations} of the ``[DIRECTIONS]`` block's ``(ACTIVITY)`` table."""
    block = blocks.get("DIRECTIONS")
    if block is None or "ACTIVITY" not in block.tables:
        raise IdentificationError(f"{path}: no [DIRECTIONS] block with an (ACTIVITY) table: which formulations act "
                                  "in which direction is not said")
    table = block.tables["ACTIVITY"]
    columns = [c.upper() for c in table.columns]
    missing = [d for d in DIRECTIONS if d not in columns]
    if missing:
        raise IdentificationError(f"{path}, line {block.line}: the (ACTIVITY) table has no column "
                                  f"{', '.join(missing)}; it needs {{ formulation FX FY FZ TX TY TZ }}")
    active = {direction: set() for direction in DIRECTIONS}
    for line, cells in table.rows:
        formulation = str(cells[0]).upper()
        if formulation not in FORMULATIONS:
            raise IdentificationError(f"{path}, line {line}: formulation {cells[0]!r} is not one of "
                                      f"{', '.join(FORMULATIONS)}")
        for direction in DIRECTIONS:
            flag = cells[columns.index(direction)]
            if flag not in (0.0, 1.0):
                raise IdentificationError(f"{path}, line {line}: {formulation} {direction} = {flag!r}: 0 or 1")
            if flag == 1.0:
                active[direction].add(formulation)
    return active


def _block(blocks, path: Path, formulation: str, direction: str):
    name = f"{formulation}_{direction}"
    if name not in blocks:
        raise IdentificationError(f"{path}: {formulation} is active in {direction} ([DIRECTIONS]) but the file has "
                                  f"no [{name}] block")
    return blocks[name]


def _constant(block, path: Path, key: str) -> float:
    if key not in block.values:
        raise IdentificationError(f"{path}, line {block.line}: [{block.name}] gives no {key}")
    line, value = block.values[key]
    if not isinstance(value, float) or not math.isfinite(value) or value < 0:
        raise IdentificationError(f"{path}, line {line}: [{block.name}] {key} = {value!r} must be a number >= 0")
    return value


def curve_axis(path: Path, block, rows, travel: float, load: float, damping: float) -> tuple[str, dict]:
    """(model, parameters) of a direction whose static force is the curve ``rows`` [(line,
    (deflection, force))] in the file's units (times ``travel`` and ``load`` to the project's):
    Kelvin-Voigt with a backbone through its points and the dashpot ``damping``; refused with the
    line where the deflections do not increase or the points are more than a backbone takes."""
    if len(rows) > MAX_KNOTS:
        raise IdentificationError(f"{path}, line {block.line}: [{block.name}] has {len(rows)} points; a backbone "
                                  f"takes 2 to {MAX_KNOTS}")
    for (line, (x0, _)), (_, (x1, _)) in zip(rows, rows[1:]):
        if not x1 > x0:
            raise IdentificationError(f"{path}, line {line + 1}: [{block.name}] deflection {x1:g} after {x0:g}: the "
                                      "deflections must increase")
    parameters = {"c": damping, "preload": 0.0}
    for i, (_, (x, f)) in enumerate(rows):
        parameters[f"backbone_x{i + 1}"] = x * travel
        parameters[f"backbone_F{i + 1}"] = f * load
    return f"{LINEAR_BASELINE.name}+backbone{len(rows)}", parameters


def units_of(blocks, path: Path) -> tuple[float, float, float, float]:
    """(length to mm, angle to rad, force to N, time to s) of the ``[UNITS]`` block."""
    return (_unit(blocks, path, "LENGTH", LENGTH_MM), _unit(blocks, path, "ANGLE", ANGLE_RAD, "radians"),
            _unit(blocks, path, "FORCE", FORCE_N), _unit(blocks, path, "TIME", TIME_S, "second"))


def read_gbs(path: str | Path) -> ImportedBushing:
    """The bushing of Altair's ``.gbs`` file ``path`` as a six-axis set (module docstring)."""
    path = Path(path)
    blocks = read_layout(path, KNOWN_BLOCKS, ".gbs", "HEADER, UNITS, GLOBAL, DIRECTIONS, FRICTION and "
                                                      "<formulation>_<direction>")
    length, angle, force, time = units_of(blocks, path)
    active = _activity(blocks, path)
    unread, axes = [], {}
    if "FRICTION" in blocks and blocks["FRICTION"].values:
        unread.append(f"[FRICTION] {dict((k, v) for k, (_, v) in blocks['FRICTION'].values.items())}")
    for direction, axis in DIRECTIONS.items():
        rotational = direction.startswith("T")
        travel = angle if rotational else length                 # file -> rad or mm
        load = force * (length if rotational else 1.0)           # file -> N.mm or N
        formulations = active[direction]
        for formulation in sorted(formulations & {"CUBIC_STIFFNESS", "RUBBER_DAMPING", "HYDROMOUNT_DAMPING"}):
            block = _block(blocks, path, formulation, direction)
            unread.append(f"[{block.name}] {dict((k, v) for k, (_, v) in block.values.items())}")
        damping = 0.0
        if "CONSTANT_DAMPING" in formulations:
            damping = _constant(_block(blocks, path, "CONSTANT_DAMPING", direction), path, "C") * load * time / travel
        if "SPLINE_STIFFNESS" in formulations:
            if "CONSTANT_STIFFNESS" in formulations:
                raise IdentificationError(f"{path}: {direction} has a spline and a constant stiffness active; give "
                                          "their sum as the spline")
            block = _block(blocks, path, "SPLINE_STIFFNESS", direction)
            table = block.tables.get("SPLINE_DATA")
            if table is None or len(table.rows) < 2:
                raise IdentificationError(f"{path}, line {block.line}: [{block.name}] needs a (SPLINE_DATA) table "
                                          "{ disp force } of at least 2 rows")
            columns = [name.lower() for name in table.columns]
            if sorted(columns) != ["disp", "force"]:
                raise IdentificationError(f"{path}, line {block.line}: [{block.name}]'s table has the columns "
                                          f"{{ {' '.join(table.columns)} }}; a spline's are {{ disp force }}")
            for line, cells in table.rows:
                if not all(isinstance(cell, float) and math.isfinite(cell) for cell in cells):
                    raise IdentificationError(f"{path}, line {line}: [{block.name}] {cells!r} is not a row of two "
                                              "finite numbers (disp, force)")
            order = (columns.index("disp"), columns.index("force"))
            rows = [(line, (cells[order[0]], cells[order[1]])) for line, cells in table.rows]
            axes[axis] = curve_axis(path, block, rows, travel, load, damping)
        else:
            stiffness = 0.0
            if "CONSTANT_STIFFNESS" in formulations:
                stiffness = _constant(_block(blocks, path, "CONSTANT_STIFFNESS", direction), path, "K") * load / travel
            elif "CUBIC_STIFFNESS" not in formulations:
                warnings.warn(f"{path}: no stiffness is active in {direction}: a free axis {axis} (k = 0)",
                              PropertyFileWarning, stacklevel=2)
            axes[axis] = (LINEAR_BASELINE.name, {"k": stiffness, "c": damping, "preload": 0.0})
    if unread:
        warnings.warn(f"{path}: read and left out (no model of the project says them so yet): " + "; ".join(unread),
                      PropertyFileWarning, stacklevel=2)
    provenance = {"imported_from": str(path), "format": FORMAT,
                  "units": {"length_to_mm": length, "angle_to_rad": angle, "force_to_N": force, "time_to_s": time}}
    return ImportedBushing(axes, provenance)
