"""A parameter file written as another tool's bushing property file: Altair's ``.gbs``.

What a linear-and-spline bushing of another tool can hold of a model: per direction its static
curve (the force at rest, v = 0 from the relaxed state, ``BushingModel.relaxed_force``, over a
stated deflection range, the mounting's offset and preload left out: installation data are the
tool's model's, not the file's) as spline data, and an equivalent linear damping at a stated
operating point, C = K''/omega with K'' the loss stiffness of the steady sine of that amplitude and
frequency (``dynamic_stiffness.data_sheet``). The header's comments say which model and file it
came from and the operating point. Numbers are written as the shortest text that reads back as
the same float, so an exported file imports (``gbs.read_gbs``) to the same curve; the damping has
10 significant digits (its loop's last digits are rounding).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fmu_src.fmi.axes import SIX_AXES, model_on_axis
from fmu_src.parameter_files import ParameterSet, read_parameter_set, read_six_axis
from identification.errors import IdentificationError
from identification.property_files.gbs import DIRECTIONS, FORMULATIONS

DIRECTION_OF_AXIS = {axis: direction for direction, axis in DIRECTIONS.items()}


@dataclass(frozen=True)
class OperatingPoint:
    """Where the curves and the damping are taken: deflections ``range_mm`` [mm] and ``range_rad``
    [rad] either side of 0 on ``points`` points; the damping's sine of ``amplitude_mm`` [mm] or
    ``amplitude_rad`` [rad] at ``frequency_hz`` [Hz]."""
    range_mm: float = 5.0
    range_rad: float = 0.1
    points: int = 21
    amplitude_mm: float = 1.0
    amplitude_rad: float = 0.02
    frequency_hz: float = 10.0

    def __post_init__(self):
        for name, unit in (("range_mm", "mm"), ("range_rad", "rad"), ("amplitude_mm", "mm"),
                           ("amplitude_rad", "rad"), ("frequency_hz", "Hz")):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise IdentificationError(f"{name} = {value!r} [{unit}] must be a finite number > 0")
        if not (isinstance(self.points, int) and 2 <= self.points <= 32):
            raise IdentificationError(f"points = {self.points!r}: 2 to 32 (a backbone's knots)")


def _axis_sets(path: Path, direction: str | None) -> dict[str, ParameterSet]:
    """{axis: its set} of a six-axis file, or of a one-axis file put on ``direction`` (FX ... TZ)."""
    if _is_six_axis(path):
        if direction is not None:
            raise IdentificationError(f"{path} is a six-axis file: every direction is written (leave out "
                                      f"--direction {direction})")
        return dict(read_six_axis(path).axes)
    one = read_parameter_set(path)
    if direction is None:
        raise IdentificationError(f"{path} is a one-axis parameter file: say which direction it is (--direction "
                                  f"FX ... TZ; one of {', '.join(DIRECTIONS)})")
    if direction not in DIRECTIONS:
        raise IdentificationError(f"direction {direction!r}: one of {', '.join(DIRECTIONS)}")
    axis = next(a for a in SIX_AXES if a.name == DIRECTIONS[direction])
    return {axis.name: ParameterSet(model_on_axis(one.model, axis), one.parameters, one.provenance)}


def _is_six_axis(path: Path) -> bool:
    """Whether the parameter file at ``path`` is a six-axis set (its model or set name says so)."""
    import json
    import xml.etree.ElementTree as ET
    from fmu_src.fmi.axes import SIX_AXIS_IDENTIFIER
    try:
        if path.suffix.lower() == ".ssv":
            return ET.parse(path).getroot().get("name") == SIX_AXIS_IDENTIFIER
        return json.loads(path.read_text(encoding="utf-8")).get("model") == SIX_AXIS_IDENTIFIER
    except (OSError, ValueError, ET.ParseError, AttributeError):
        return False          # the one-axis reader says what is wrong with it


def _curve_and_damping(one: ParameterSet, rotational: bool, point: OperatingPoint) -> tuple[np.ndarray, np.ndarray, float]:
    """(deflections, static forces, equivalent damping) of one axis in the project's units."""
    from identification.forward.dynamic_stiffness import SteadyStateLoop, data_sheet
    model = one.model
    values = model.check(one.parameters)
    constants = model.constants(values)
    reach = point.range_rad if rotational else point.range_mm
    x = np.linspace(-reach, reach, point.points)
    force = np.array([model.relaxed_force(constants, float(xi)) for xi in x])
    if not np.all(np.isfinite(force)):
        raise IdentificationError(f"the {model.name} model's static force is not finite over +-{reach:g}")
    amplitude = point.amplitude_rad if rotational else point.amplitude_mm
    sheet = data_sheet(model, [values], [amplitude], [point.frequency_hz], 0.0, SteadyStateLoop())
    omega = 2.0 * math.pi * point.frequency_hz
    damping = float(sheet.loss_N_per_mm[0]) / omega
    if damping < 0.0:
        # a loss stiffness at rounding's size (an axis without damping) is none; a real one is refused
        if -damping > 1e-9 * abs(float(sheet.storage_N_per_mm[0])) / omega:
            raise IdentificationError(f"the {model.name} model's equivalent damping at {amplitude:g}, "
                                      f"{point.frequency_hz:g} Hz is {damping:g} < 0: it puts energy in")
        damping = 0.0
    return x, force, damping


def gbs_text(path: str | Path, point: OperatingPoint = OperatingPoint(), direction: str | None = None) -> str:
    """The ``.gbs`` text of the parameter file ``path`` (six-axis, or one-axis on ``direction``):
    per direction present a spline stiffness and a constant damping (module docstring), in mm,
    rad, N and s."""
    path = Path(path)
    sets = _axis_sets(path, direction)
    blocks, active = [], {formulation: {d: 0 for d in DIRECTIONS} for formulation in FORMULATIONS}
    described = []
    for axis in SIX_AXES:
        if axis.name not in sets:
            continue
        one = sets[axis.name]
        d = DIRECTION_OF_AXIS[axis.name]
        x, force, damping = _curve_and_damping(one, axis.rotational, point)
        active["SPLINE_STIFFNESS"][d] = active["CONSTANT_DAMPING"][d] = 1
        blocks += [f"[SPLINE_STIFFNESS_{d}]", "(SPLINE_DATA)", "{ disp force }"]
        blocks += [f"{xi!r} {fi!r}" for xi, fi in zip(x.tolist(), force.tolist())]
        blocks += [f"[CONSTANT_DAMPING_{d}]", f"C = {format(damping, '.10g')}"]
        described.append(f"$ {d}: {one.model.name}")
    amplitude = f"{point.amplitude_mm:g} mm / {point.amplitude_rad:g} rad"
    header = ["$ written by bushing-identify export: the static curve and an equivalent linear damping of",
              f"$ {path.name}; curves over +-{point.range_mm:g} mm and +-{point.range_rad:g} rad on {point.points} "
              f"points, the damping K''/omega of a {amplitude} sine at {point.frequency_hz:g} Hz", *described,
              "[HEADER]", "FILE_TYPE = 'gbs'", "FILE_VERSION = 1.0", "FILE_FORMAT = 'ASCII'",
              "[UNITS]", "LENGTH = 'mm'", "ANGLE = 'radians'", "FORCE = 'newton'", "MASS = 'kg'", "TIME = 'second'",
              "[GLOBAL]", "FORCE_COUPLING = 0", "MOMENT_COUPLING = 0",
              "[DIRECTIONS]", "(ACTIVITY)", "{ formulation FX FY FZ TX TY TZ }"]
    header += [f"'{formulation}' " + " ".join(str(active[formulation][d]) for d in DIRECTIONS)
               for formulation in FORMULATIONS]
    return "\n".join(header + blocks) + "\n"


def export_gbs(path: str | Path, out: str | Path, point: OperatingPoint = OperatingPoint(),
               direction: str | None = None) -> Path:
    """Write :func:`gbs_text` of ``path`` to ``out``; returns ``out``."""
    out = Path(out)
    out.write_text(gbs_text(path, point, direction), encoding="utf-8")
    return out
