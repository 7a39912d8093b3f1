"""Multi-axis rig tests: a bushing driven along two or three axes at once, its force vector measured,
and a model's prediction of them, coupled or not (``axes.Coupling``).

CSV, comma separated, a header row, ``#`` comment lines first::

    time_s,dx_mm,dy_mm,Fx_N,Fy_N            the plane (x, y: a radial group)
    time_s,dx_mm,dy_mm,dz_mm,Fx_N,Fy_N,Fz_N  3-space (a spherical group)

with, optionally, measured velocities ``vx_mm_s,vy_mm_s[,vz_mm_s]`` (every axis's or none). Time in
s, increasing; displacements in mm, forces in N (the one-axis files' units). A file that cannot be
used is refused with its name, the line or the column, and what is allowed.

A model predicts a multi-axis test (:func:`simulate_multiaxis`) as the six-axis FMU runs it with
the input the FMU guide advises: a communication point at every sample, the displacement straight
between samples with the secant velocity (a measured velocity column is read and kept, not used:
fed beside a sampled displacement it would make the dashpots carry a jump at every step), coupled
(the model's coupled form on the displacement vector, ``model_definition.CoupledKernels``) or
uncoupled (its one-axis model on each axis alone). Compiled with numba (``compiled_core``).
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fmu_src.bushing_models import BushingModel
from identification.errors import IdentificationError

AXIS_NAMES = ("x", "y", "z")


@dataclass(frozen=True)
class MultiAxisMeasurement:
    """One multi-axis test: d = 2 or 3 axes (x, y[, z])."""
    source: str
    time_s: np.ndarray              # (n,)
    displacement_mm: np.ndarray     # (n, d)
    force_N: np.ndarray             # (n, d)
    velocity_mm_s: np.ndarray | None = None   # (n, d), measured; None: the secant velocity

    @property
    def axes(self) -> tuple[str, ...]:
        return AXIS_NAMES[:self.displacement_mm.shape[1]]

    @property
    def name(self) -> str:
        return Path(self.source).name


def load_multiaxis(path: str | Path) -> MultiAxisMeasurement:
    """Read a multi-axis test (module docstring); IdentificationError names the file, the line or
    the column, and what is allowed."""
    path = Path(path)
    if not path.is_file():
        raise IdentificationError(f"multi-axis file {path} does not exist")
    with open(path, newline="", encoding="utf-8") as handle:
        lines = [(number, line) for number, line in enumerate(handle, start=1) if line.strip()
                 and not line.lstrip().startswith("#")]
    if not lines:
        raise IdentificationError(f"{path}: no header row (time_s,dx_mm,dy_mm,Fx_N,Fy_N ...)")
    header_line, header_text = lines[0]
    header = [name.strip() for name in next(csv.reader([header_text]))]
    axes = AXIS_NAMES[:3 if "dz_mm" in header or "Fz_N" in header else 2]
    wanted = ["time_s"] + [f"d{a}_mm" for a in axes] + [f"F{a}_N" for a in axes]
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
    return MultiAxisMeasurement(str(path), t, pick([f"d{a}_mm" for a in axes]), pick([f"F{a}_N" for a in axes]),
                                pick(velocities) if given else None)


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


def simulate_multiaxis(parameters, time_s, displacement_mm, model: str | BushingModel | None = None,
                       coupled: bool = True) -> np.ndarray:
    """The force vectors [N], (samples, d), of a parameter set on a multi-axis path ``displacement_mm``
    (samples, d = 2 or 3) at the times ``time_s``, as the six-axis FMU gives them (module docstring):
    ``coupled`` the model's coupled form on the displacement vector, else its one-axis model on each
    axis alone. The bushing starts relaxed at the first sample. ``parameters``: any form
    ``parameter_input`` takes (a mounting's offset and preload apply to every axis alike)."""
    from identification.compiled_core import simulate_coupled_held, simulate_population_held
    from identification.parameter_input import parameter_sets
    bushing, sets = parameter_sets(parameters, model)
    values = sets[0]
    t = np.ascontiguousarray(time_s, dtype=float)
    x = np.atleast_2d(np.asarray(displacement_mm, dtype=float))
    if x.ndim != 2 or x.shape[0] != t.size or x.shape[1] not in (2, 3):
        raise ValueError(f"displacement_mm must be (samples, 2 or 3) with one row per time, got {x.shape} for "
                         f"{t.size} times")
    offset, preload = bushing.mounting(values)
    x = x - offset
    secant = np.vstack([np.diff(x, axis=0) / np.diff(t)[:, None], np.zeros((1, x.shape[1]))])
    if coupled and bushing.coupled is not None:
        return simulate_coupled_held([values], t, x, secant, model=bushing)[0] + preload
    # uncoupled, or Kelvin-Voigt, whose linear elements couple nothing
    return np.column_stack([simulate_population_held([values], t, x[:, c], secant[:, c], model=bushing)[0]
                            for c in range(x.shape[1])]) + preload


def vector_nrmse(predicted: np.ndarray, measured: np.ndarray) -> float:
    """rms |F_pre - F_exp| over rms |F_exp| of force vectors (samples, d)."""
    return float(np.sqrt(np.mean(np.sum((predicted - measured) ** 2, axis=1)) / np.mean(np.sum(measured ** 2, axis=1))))
