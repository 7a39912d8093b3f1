"""Read and write measured bushing tests (CSV).

Format: optional comment lines starting with ``#`` (provenance; synthetic files say so
there), then a header naming columns with their units, then comma-separated numbers:

    time_s,displacement_mm,force_N[,velocity_mm_s]

Other declared units are converted: displacement in m, mm, in; force in N, kN, lbf, kip;
velocity in m_s, mm_s, in_s (per second). Internal units: s, mm, N, mm/s.

When the velocity is absent it is derived from the displacement with second-order finite
differences (``numpy.gradient``: central in the interior, one-sided at both ends), which
amplifies displacement noise by about 1/(sqrt(2)*dt).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from identification.errors import IdentificationError

LENGTH_TO_MM = {"mm": 1.0, "m": 1000.0, "in": 25.4}
FORCE_TO_N = {"N": 1.0, "kN": 1000.0, "lbf": 4.4482216152605, "kip": 4448.2216152605}
VELOCITY_TO_MM_S = {"mm_s": 1.0, "m_s": 1000.0, "in_s": 25.4}
MIN_SAMPLES = 10


class MeasurementError(IdentificationError):
    """A measurement file that cannot be used; the message names the file, column and row."""


@dataclass
class Measurement:
    time_s: np.ndarray
    displacement_mm: np.ndarray
    force_N: np.ndarray
    velocity_mm_s: np.ndarray
    velocity_derived: bool = False
    source: str = ""
    comments: list[str] = field(default_factory=list)
    has_force: bool = True      # False: an input file without a force column (force_N is zeros)

    def __len__(self) -> int:
        return self.time_s.size

    @property
    def measured_velocity_mm_s(self) -> np.ndarray | None:
        """The velocity column if the file has one, else None (the forward model then derives
        the velocity from its interpolant of the displacement)."""
        return None if self.velocity_derived else self.velocity_mm_s


def derive_velocity(time_s: np.ndarray, displacement_mm: np.ndarray) -> np.ndarray:
    """dx/dt [mm/s] by second-order finite differences (see the module docstring)."""
    return np.gradient(displacement_mm, time_s, edge_order=2)


def _column_factor(path: Path, header: str, quantity: str, table: dict[str, float]) -> float:
    unit = header[len(quantity) + 1:]
    if unit not in table:
        allowed = ", ".join(f"{quantity}_{u}" for u in table)
        raise MeasurementError(f"{path}: column {header!r} has unknown unit {unit!r}; allowed: {allowed}")
    return table[unit]


def load_measurement(path: str | Path, force_optional: bool = False) -> Measurement:
    """Load a measurement CSV; raise MeasurementError naming what is wrong and where.
    ``force_optional``: accept a file without a force column (an input to predict)."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except FileNotFoundError:
        raise MeasurementError(f"measurement file {path} does not exist") from None
    comments = [line[1:].strip() for line in lines if line.startswith("#")]
    body = [(number, line) for number, line in enumerate(lines, start=1)
            if line.strip() and not line.startswith("#")]
    if not body:
        raise MeasurementError(f"{path}: no header line")
    header_line, header = body[0]
    names = [name.strip() for name in header.split(",")]

    columns: dict[str, tuple[int, float]] = {}
    for quantity, table in (("time", {"s": 1.0}), ("displacement", LENGTH_TO_MM),
                            ("force", FORCE_TO_N), ("velocity", VELOCITY_TO_MM_S)):
        matches = [i for i, name in enumerate(names) if name.split("_")[0] == quantity]
        if len(matches) > 1:
            raise MeasurementError(f"{path}: more than one {quantity} column in header {header!r}")
        if matches:
            columns[quantity] = (matches[0], _column_factor(path, names[matches[0]], quantity, table))
    missing = [q for q in ("time", "displacement", "force") if q not in columns
               and not (q == "force" and force_optional)]
    if missing:
        raise MeasurementError(
            f"{path}: header {header!r} (line {header_line}) lacks column(s) {', '.join(missing)}; "
            "expected time_s,displacement_mm,force_N[,velocity_mm_s]")

    rows = body[1:]
    if len(rows) < MIN_SAMPLES:
        raise MeasurementError(f"{path}: {len(rows)} samples; at least {MIN_SAMPLES} are needed")
    data = np.empty((len(rows), len(names)))
    for r, (number, line) in enumerate(rows):
        fields = line.split(",")
        if len(fields) != len(names):
            raise MeasurementError(f"{path}, line {number}: {len(fields)} fields, header has {len(names)}")
        for c, text in enumerate(fields):
            try:
                value = float(text)
            except ValueError:
                raise MeasurementError(f"{path}, line {number}: {names[c]} = {text.strip()!r} is not a number") from None
            if not math.isfinite(value):
                raise MeasurementError(f"{path}, line {number}: {names[c]} = {text.strip()} is not finite")
            data[r, c] = value

    def column(quantity):
        index, factor = columns[quantity]
        return data[:, index] * factor

    time_s = column("time")
    steps = np.diff(time_s)
    if np.any(steps <= 0):
        bad = int(np.argmax(steps <= 0))
        raise MeasurementError(f"{path}, line {rows[bad + 1][0]}: time {time_s[bad + 1]} s does not "
                               f"increase (previous sample {time_s[bad]} s)")
    displacement = column("displacement")
    derived = "velocity" not in columns
    velocity = derive_velocity(time_s, displacement) if derived else column("velocity")
    has_force = "force" in columns
    force = column("force") if has_force else np.zeros_like(time_s)
    return Measurement(time_s, displacement, force, velocity, derived, str(path), comments, has_force)


def write_measurement(path: str | Path, time_s, displacement_mm, force_N, comments: list[str] = ()) -> None:
    """Write time_s,displacement_mm,force_N with ``# `` comment lines first."""
    table = np.column_stack([time_s, displacement_mm, force_N])
    header = "".join(f"# {line}\n" for line in comments)
    with open(path, "w", encoding="utf-8") as stream:
        stream.write(header + "time_s,displacement_mm,force_N\n")
        np.savetxt(stream, table, delimiter=",", fmt=["%.6f", "%.6f", "%.4f"])
