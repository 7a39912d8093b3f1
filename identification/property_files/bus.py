"""Adams' nonlinear bushing property files (``.bus``, TeimOrbit), read as a six-axis set.

The layout (the issue that asked for it describes it so; no documented example was at hand, so
the reader is checked against that description only): ``[MDI_HEADER]``, ``[UNITS]`` (``LENGTH``,
``ANGLE``, ``FORCE``, ``MASS``, ``TIME``), ``[DAMPING]`` with six constants, and one curve per
direction, ``[FX_CURVE]``, ``[FY_CURVE]``, ``[FZ_CURVE]`` (deflection, force) and ``[TX_CURVE]``,
``[TY_CURVE]``, ``[TZ_CURVE]`` (angle, torque), each a two-column table; ``$`` comments.

The damping's six keys name the directions in one of two ways, both taken: the curves' own
(``FX``, ``FY``, ``FZ``, ``TX``, ``TY``, ``TZ``, optionally ending in ``_DAMPING``), or translation
and rotation (``TX``, ``TY``, ``TZ`` with ``RX``, ``RY``, ``RZ``); which one a file uses its keys say
(an ``RX`` key: the second), and a mix is refused.

Read here (:func:`read_bus`): per direction Kelvin-Voigt with the ``backbone<K>`` option through
the curve's points (2 to 32) and the damping as its dashpot, in the project's units (mm, rad, N,
N.mm, s; the damping in N.s/mm and N.mm.s/rad). A direction without a curve is a free axis,
warned. Refused with the file and line: a unit the reader does not know, a curve that is not two
columns of numbers or whose deflection does not increase, a damping key it cannot place, a negative
damping, a block the layout does not know.
"""
from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

from fmu_src.model.registry import LINEAR_BASELINE
from identification.errors import IdentificationError
from identification.property_files.chrono_json import ImportedBushing, PropertyFileWarning
from identification.property_files.gbs import DIRECTIONS, curve_axis, units_of
from identification.property_files.teimorbit import read_layout

FORMAT = "bus"
CURVES = {f"{direction}_CURVE": direction for direction in DIRECTIONS}
KNOWN_BLOCKS = {"MDI_HEADER", "UNITS", "DAMPING"} | set(CURVES)
TRANSLATION_ROTATION = {"TX": "FX", "TY": "FY", "TZ": "FZ", "RX": "TX", "RY": "TY", "RZ": "TZ"}
"""The second naming of the damping's keys (translation T, rotation R) in the curves' directions."""


def _damping(blocks, path: Path) -> dict[str, float]:
    """{direction (FX ... TZ): damping in the file's units} of the ``[DAMPING]`` block."""
    block = blocks.get("DAMPING")
    if block is None:
        warnings.warn(f"{path}: no [DAMPING] block: every axis undamped", PropertyFileWarning, stacklevel=3)
        return {}
    keys = {re.sub(r"_DAMPING$", "", key): key for key in block.values}
    rotation_named = any(key in ("RX", "RY", "RZ") for key in keys)
    names = TRANSLATION_ROTATION if rotation_named else {d: d for d in DIRECTIONS}
    out = {}
    for short, key in keys.items():
        line, value = block.values[key]
        if short not in names or (rotation_named and short.startswith("F")):
            raise IdentificationError(f"{path}, line {line}: [DAMPING] {key} names no direction; the keys are FX, FY, "
                                      "FZ, TX, TY, TZ (the curves', optionally with _DAMPING) or TX, TY, TZ with RX, "
                                      "RY, RZ (translation and rotation), one naming per file")
        if not isinstance(value, float) or not math.isfinite(value) or value < 0:
            raise IdentificationError(f"{path}, line {line}: [DAMPING] {key} = {value!r} must be a number >= 0 (a "
                                      "negative dashpot adds energy)")
        out[names[short]] = value
    return out


def read_bus(path: str | Path) -> ImportedBushing:
    """The bushing of the Adams ``.bus`` file ``path`` as a six-axis set (module docstring)."""
    path = Path(path)
    blocks = read_layout(path, KNOWN_BLOCKS, ".bus", "MDI_HEADER, UNITS, DAMPING and FX_CURVE ... TZ_CURVE")
    length, angle, force, time = units_of(blocks, path)
    damping = _damping(blocks, path)
    axes = {}
    for direction, axis in DIRECTIONS.items():
        rotational = direction.startswith("T")
        travel = angle if rotational else length
        load = force * (length if rotational else 1.0)
        c = damping.get(direction, 0.0) * load * time / travel
        block = blocks.get(f"{direction}_CURVE")
        if block is None:
            warnings.warn(f"{path}: no [{direction}_CURVE]: a free axis {axis} (k = 0)", PropertyFileWarning,
                          stacklevel=2)
            axes[axis] = (LINEAR_BASELINE.name, {"k": 0.0, "c": c, "preload": 0.0})
            continue
        table = block.tables.get("")
        if table is None or len(table.columns) != 2 or len(table.rows) < 2:
            raise IdentificationError(f"{path}, line {block.line}: [{block.name}] needs a two-column table "
                                      "{ deflection force } of at least 2 rows")
        for line, cells in table.rows:
            if not all(isinstance(cell, float) and math.isfinite(cell) for cell in cells):
                raise IdentificationError(f"{path}, line {line}: [{block.name}] {cells!r} is not a row of two finite "
                                          "numbers")
        axes[axis] = curve_axis(path, block, table.rows, travel, load, c)
    provenance = {"imported_from": str(path), "format": FORMAT,
                  "units": {"length_to_mm": length, "angle_to_rad": angle, "force_to_N": force, "time_to_s": time}}
    return ImportedBushing(axes, provenance)
