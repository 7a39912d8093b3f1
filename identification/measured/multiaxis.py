"""Multi-axis rig tests: a bushing driven along two or three axes at once, its force vector measured,
and a model's prediction of them, coupled or not (``axes.Coupling``).

CSV, comma separated, a header row, ``#`` comment lines first::

    time_s,dx_mm,dy_mm,Fx_N,Fy_N            the plane (x, y: a radial group)
    time_s,dx_mm,dy_mm,dz_mm,Fx_N,Fy_N,Fz_N  3-space (a spherical group)

with, optionally, measured velocities ``vx_mm_s,vy_mm_s[,vz_mm_s]`` (every axis's or none). Time in
s, increasing; displacements in mm, forces in N (the one-axis files' units). A file that cannot be
used is refused with its name, the line or the column, and what is allowed.

A model predicts a multi-axis test (``identification.forward.simulate.simulate_multiaxis``) as the fit's forward model drives a
one-axis test (``identification.forward.input_path``): each axis's interpolant of its samples (the
Hermite one where the velocity was measured), on one grid of communication points for every axis;
coupled (the model's coupled form on the displacement vector, ``definition.CoupledKernels``)
or not (its one-axis model on each axis alone): :data:`COUPLED_AXES`. Compiled with numba
(``population``). The six-axis FMU, a co-simulation slave, holds the secant velocity over each
communication step instead (``population.simulate_coupled_held``); at 1 kHz on a 10 Hz circle the
two differ by a few 1e-3 of the force, and the interpolant's is closer to the continuous-time force
(``tests/identification/measured/test_multiaxis.py``).

Multi-axis tests train a fit (``fit(..., multiaxis=[...], coupling=...)``, ``fit --multiaxis FILE
--coupling radial``) as one-axis tests do: every axis's force at every sample a residual in that
axis's noise units (``identification.fitting.objectives``).
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fmu_src.model.registry import BushingModel
from identification.errors import IdentificationError

AXIS_NAMES = ("x", "y", "z")


@dataclass(frozen=True)
class MultiAxisMeasurement:
    """One multi-axis test: d = 2 or 3 axes (x, y[, z])."""
    source: str
    time_s: np.ndarray              # (n,)
    displacement_mm: np.ndarray     # (n, d)
    force_N: np.ndarray             # (n, d)
    velocity_mm_s: np.ndarray | None = None   # (n, d), measured; None: from the displacement's interpolant
    has_force: bool = True      # False: a path without force columns (force_N is zeros)

    @property
    def axes(self) -> tuple[str, ...]:
        return AXIS_NAMES[:self.displacement_mm.shape[1]]

    @property
    def name(self) -> str:
        return Path(self.source).name

    def components(self) -> list:
        """Each axis as a one-axis ``measurements.Measurement`` (its displacement, force and velocity,
        measured or derived): what scales a fit's search and fits Kelvin-Voigt's linear law."""
        from identification.measured.measurements import Measurement, derive_velocity
        return [Measurement(self.time_s, self.displacement_mm[:, c], self.force_N[:, c],
                            self.velocity_mm_s[:, c] if self.velocity_mm_s is not None
                            else derive_velocity(self.time_s, self.displacement_mm[:, c]),
                            velocity_derived=self.velocity_mm_s is None, source=f"{self.source} ({axis})")
                for c, axis in enumerate(self.axes)]


def _data_lines(path: Path) -> list[tuple[int, str]]:
    """(line number, text) of the lines that are neither blank nor ``#`` comments."""
    with open(path, newline="", encoding="utf-8") as handle:
        return [(number, line) for number, line in enumerate(handle, start=1) if line.strip()
                and not line.lstrip().startswith("#")]


def is_multiaxis_file(path: str | Path) -> bool:
    """Whether a CSV's header names multi-axis columns (``dx_mm``), as opposed to a one-axis test's."""
    lines = _data_lines(Path(path)) if Path(path).is_file() else []
    return bool(lines) and "dx_mm" in [name.strip() for name in next(csv.reader([lines[0][1]]))]


def load_multiaxis(path: str | Path, force_optional: bool = False) -> MultiAxisMeasurement:
    """Read a multi-axis test (module docstring); IdentificationError names the file, the line or
    the column, and what is allowed. ``force_optional``: a path without force columns is read too
    (``has_force`` False, forces 0), as ``predict`` takes one."""
    path = Path(path)
    if not path.is_file():
        raise IdentificationError(f"multi-axis file {path} does not exist")
    lines = _data_lines(path)
    if not lines:
        raise IdentificationError(f"{path}: no header row (time_s,dx_mm,dy_mm,Fx_N,Fy_N ...)")
    header_line, header_text = lines[0]
    header = [name.strip() for name in next(csv.reader([header_text]))]
    axes = AXIS_NAMES[:3 if "dz_mm" in header or "Fz_N" in header else 2]
    forces = [f"F{a}_N" for a in axes]
    has_force = not (force_optional and not any(name in header for name in forces))
    wanted = ["time_s"] + [f"d{a}_mm" for a in axes] + (forces if has_force else [])
    missing = [name for name in wanted if name not in header]
    if missing:
        raise IdentificationError(f"{path}, line {header_line}: missing column{'s' if len(missing) > 1 else ''} "
                                  f"{', '.join(missing)}; a multi-axis file has time_s,dx_mm,dy_mm,Fx_N,Fy_N (and "
                                  "dz_mm,Fz_N for three axes; vx_mm_s,vy_mm_s[,vz_mm_s] if the velocity was measured)")
    velocities = [f"v{a}_mm_s" for a in axes]
    given = [name for name in velocities if name in header]
    if given and len(given) != len(velocities):
        raise IdentificationError(f"{path}, line {header_line}: velocity columns {', '.join(given)} without "
                                  f"{', '.join(sorted(set(velocities) - set(given)))}: give every axis's velocity "
                                  "or none")
    unknown = [name for name in header if name not in wanted + velocities]
    if unknown:
        raise IdentificationError(f"{path}, line {header_line}: unknown columns {', '.join(unknown)}; allowed: "
                                  f"{', '.join(wanted + velocities)}")
    columns = {name: i for i, name in enumerate(header)}
    rows = []
    for number, text in lines[1:]:
        values = next(csv.reader([text]))
        if len(values) != len(header):
            raise IdentificationError(f"{path}, line {number}: {len(values)} values, the header has {len(header)} "
                                      f"({', '.join(header)})")
        try:
            rows.append([float(value) for value in values])
        except ValueError:
            raise IdentificationError(f"{path}, line {number}: {text.strip()!r} holds a value that is not a "
                                      "number") from None
        if not all(math.isfinite(value) for value in rows[-1]):
            raise IdentificationError(f"{path}, line {number}: a value is not finite ({text.strip()})")
    if len(rows) < 2:
        raise IdentificationError(f"{path}: {len(rows)} sample(s); a test needs at least 2")
    table = np.array(rows)
    t = table[:, columns["time_s"]]
    if not np.all(np.diff(t) > 0):
        bad = int(np.argmax(np.diff(t) <= 0)) + 1
        raise IdentificationError(f"{path}, line {lines[1 + bad][0]}: time {t[bad]} s does not increase (after "
                                  f"{t[bad - 1]} s)")
    pick = lambda names: table[:, [columns[name] for name in names]]   # noqa: E731
    displacement = pick([f"d{a}_mm" for a in axes])
    return MultiAxisMeasurement(str(path), t, displacement, pick(forces) if has_force else np.zeros_like(displacement),
                                pick(velocities) if given else None, has_force)


def write_multiaxis(path: str | Path, time_s, displacement_mm, force_N, comments=()) -> Path:
    """Write a multi-axis test (``#`` comment lines, then the header and the columns)."""
    displacement, force = np.atleast_2d(displacement_mm), np.atleast_2d(force_N)
    axes = AXIS_NAMES[:displacement.shape[1]]
    header = ["time_s"] + [f"d{a}_mm" for a in axes] + [f"F{a}_N" for a in axes]
    path = Path(path)
    with open(path, "w", encoding="utf-8") as handle:
        handle.write("".join(f"# {line}\n" for line in comments) + ",".join(header) + "\n")
        np.savetxt(handle, np.column_stack([time_s, displacement, force]), delimiter=",",
                   fmt=["%.6f"] + ["%.6f"] * len(axes) + ["%.4f"] * len(axes))
    return path


COUPLED_AXES = {"none": 0, "radial": 2, "spherical": 3}
"""The couplings a multi-axis test is run with, and how many of its leading axes each couples: none,
one model per axis; radial, x and y (z, if the test has it, on its own); spherical, x, y and z."""


def coupled_axes(coupling: str, measurement: MultiAxisMeasurement | int) -> int:
    """The leading axes ``coupling`` (one of COUPLED_AXES) runs coupled on ``measurement`` (or on a
    test of that many axes); IdentificationError for an unknown coupling, or spherical on a plane test."""
    if coupling not in COUPLED_AXES:
        raise IdentificationError(f"unknown coupling {coupling!r} for a multi-axis test; allowed: "
                                  f"{', '.join(COUPLED_AXES)}")
    axes = measurement if isinstance(measurement, int) else measurement.displacement_mm.shape[1]
    if COUPLED_AXES[coupling] > axes:
        where = "" if isinstance(measurement, int) else f"{measurement.source}: "
        raise IdentificationError(f"{where}the {coupling} coupling needs {COUPLED_AXES[coupling]} axes (dz_mm, Fz_N); "
                                  f"this test has {axes} (x, y): use radial or none")
    return COUPLED_AXES[coupling]


def vector_nrmse(predicted: np.ndarray, measured: np.ndarray) -> float:
    """rms |F_pre - F_exp| over rms |F_exp| of force vectors (samples, d)."""
    return float(np.sqrt(np.mean(np.sum((predicted - measured) ** 2, axis=1)) / np.mean(np.sum(measured ** 2, axis=1))))
