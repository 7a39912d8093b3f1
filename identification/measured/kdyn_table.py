"""The dynamic-stiffness table: its CSV file (the one module that reads and writes it) and the
table as training data, what a supplier's data sheet gives.

The file: ``#`` comment lines, a header, one row per case. Each row is one sine of amplitude X
[mm] about the preload P [mm] at frequency f [Hz], its dynamic stiffness |K*| [N/mm] and loss
angle delta [deg] (first harmonic, steady state). Read (``load_kdyn_table``): the columns
``amplitude_mm,frequency_hz,kdyn_N_per_mm,loss_angle_deg`` (REQUIRED), optionally
``preload_mm`` (default 0) and ``weight`` (default 1; 0 leaves a row out), in any order, other
columns ignored. Written (``write_kdyn_table``, which ``DynamicStiffness.to_csv`` and so
``python -m identification characterise`` use): SHEET_COLUMNS (the case, then |K*|, delta,
K' = |K*|cos(delta), K'' = |K*|sin(delta) [N/mm], the energy per cycle [mJ] and the peak force
[N]), an ensemble's ``<column>_min``, ``<column>_max`` after them, every number with
NUMBER_FORMAT (10 significant digits): a computed table reads back, each number the one written.
Checks on reading: a value that is not a finite number, an amplitude, frequency or |K*| <= 0, a
loss angle outside 0-90 deg, a negative weight, a case given twice are errors naming line and
column; an amplitude above PLAUSIBLE_AMPLITUDE_MM or a frequency above PLAUSIBLE_FREQUENCY_HZ
warns (a unit mistake, most likely).

Residuals (``identification.fitting.objectives``): per row, the relative |K*| error over
KDYN_UNCERTAINTY and the loss-angle error over LOSS_ANGLE_UNCERTAINTY_DEG, each times the row's
weight: the table's errors in units of a typical forced-vibration test's uncertainty (ISO
4664-1 rigs quote about 1 % on |K*| and a few tenths of a degree on delta), as a time series's
residuals are in units of its noise. A fit at the table's floor has an rms of both at most
``result.FLOOR_FACTOR``.

Model side: the compiled sine loop (``identification.forward.steady_state``) with FIT_STEPS_PER_CYCLE
steps per cycle for exactly FIT_CYCLES cycles from rest at the preload, or a model's settling
time where it declares a longer one (``BushingModel.settling_s``; a fixed count per row keeps the
misfit a smooth function of the parameters; a steady-state test would make it jump from one
candidate to the next); the screening and the early stages use a coarser loop
(SEARCH_STEPS_PER_CYCLE, SEARCH_CYCLES; ``objectives.PreparedTable``). The fit checks, at its result, how far the last of
these cycles is from the converged table (``FitResult.summary``).
"""
from __future__ import annotations

import csv
import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from identification.errors import CharacterisationWarning, IdentificationError
from identification.measured.measurements import temperature_column_K, temperature_column_of

KDYN_UNCERTAINTY = 0.01
LOSS_ANGLE_UNCERTAINTY_DEG = 0.2
FIT_STEPS_PER_CYCLE = 64
"""The secant path through 64 samples per cycle carries a first harmonic (pi/64)^2/3 = 8e-4
smaller than the sine's: a tenth of KDYN_UNCERTAINTY."""
FIT_CYCLES = 6
"""From rest, the sixth cycle's first harmonic is within about a tenth of the uncertainties of the
steady state for the paper's Tables 2, 4, 5 on 0.5-3 mm, 1-30 Hz (docs/benchmarks.md, "Figures
behind the code's constants"); twelve cycles would halve little."""
SEARCH_STEPS_PER_CYCLE, SEARCH_CYCLES = 32, 3
"""The table's loop during the screening and the early least-squares stages, which only choose the
basins the last stage refines: a quarter of the cost, near the steady state at the truth for
Tables 2, 4, 5; the Table 4 round trip (benchmarks/bench_kdyn_fit.py) is as accurate with either,
and faster with 3 (docs/benchmarks.md, "Figures behind the code's constants")."""
REQUIRED = ("amplitude_mm", "frequency_hz", "kdyn_N_per_mm", "loss_angle_deg")
"""The columns a table to read must have (units in the names)."""
OPTIONAL = {"preload_mm": 0.0, "weight": 1.0}
"""The columns a table to read may have, with the value a missing one stands for."""
COLUMNS = ("amplitude_mm", "frequency_hz", "preload_mm", "kdyn_N_per_mm", "loss_angle_deg", "weight")
"""KdynTable's columns, in its field order."""
SHEET_COLUMNS = ("amplitude_mm", "frequency_hz", "preload_mm", "kdyn_N_per_mm", "loss_angle_deg", "storage_N_per_mm",
                 "loss_N_per_mm", "energy_per_cycle_mJ", "peak_force_N")
"""The columns ``characterise`` writes (``dynamic_stiffness.COLUMNS``), in their order."""
SHEET_RESULT_COLUMNS = SHEET_COLUMNS[3:]
"""The columns computed per case (the first three describe the case); an ensemble's min and max
of each follow them (``ensemble_columns``)."""
NUMBER_FORMAT = ".10g"
"""How ``write_kdyn_table`` writes every number."""
PLAUSIBLE_AMPLITUDE_MM = 50.0
PLAUSIBLE_FREQUENCY_HZ = 500.0
"""Above these, a bushing test is unlikely: a table or a grid that goes beyond warns."""


def ensemble_columns(names: Sequence[str] = SHEET_RESULT_COLUMNS) -> list[str]:
    """The columns of an ensemble's min and max: ``<column>_min``, ``<column>_max`` per column."""
    return [f"{name}_{bound}" for name in names for bound in ("min", "max")]


def write_kdyn_table(path: str | Path, columns: Mapping[str, np.ndarray], comments: Sequence[str] = ()) -> Path:
    """Write a table: ``comments`` first, as ``# `` lines, then the header (``columns``' names, in
    their order; REQUIRED among them) and one row per case, every number with NUMBER_FORMAT.
    ``load_kdyn_table`` reads it back. Returns ``path``."""
    path = Path(path)
    missing = [name for name in REQUIRED if name not in columns]
    if missing:
        raise IdentificationError(f"{path}: a dynamic-stiffness table needs the column(s) {', '.join(missing)}")
    arrays = [np.asarray(values) for values in columns.values()]
    if len({array.shape for array in arrays}) != 1 or arrays[0].ndim != 1:
        raise IdentificationError(f"{path}: the table's columns must be 1-D arrays of equal length")
    with open(path, "w", newline="") as handle:
        handle.writelines(f"# {line}\n" for line in comments)
        writer = csv.writer(handle)
        writer.writerow(list(columns))
        for i in range(arrays[0].size):
            writer.writerow([format(array[i], NUMBER_FORMAT) for array in arrays])
    return path


@dataclass(frozen=True)
class KdynTable:
    """The rows of a dynamic-stiffness table (arrays of equal length; units in the names)."""
    amplitude_mm: np.ndarray
    frequency_hz: np.ndarray
    preload_mm: np.ndarray
    kdyn_N_per_mm: np.ndarray
    loss_angle_deg: np.ndarray
    weight: np.ndarray
    source: str = "table"
    temperature_K: np.ndarray | None = None
    """The rubber's temperature [K] of each row (a ``temperature_C`` or ``temperature_K`` column);
    None: the table says none (a model with a temperature law takes its set's)."""

    def __post_init__(self):
        columns = [getattr(self, name) for name in COLUMNS]
        if self.temperature_K is not None:
            columns.append(self.temperature_K)
        if len({np.shape(c) for c in columns}) != 1 or np.ndim(self.amplitude_mm) != 1:
            raise IdentificationError(f"{self.source}: the table's columns must be 1-D arrays of equal length")
        columns = columns[:len(COLUMNS)]
        for row in range(len(self.amplitude_mm)):
            values = {name: float(column[row]) for name, column in zip(COLUMNS, columns)}
            for name, value in values.items():
                if not math.isfinite(value):
                    raise IdentificationError(f"{self.source}, row {row + 1}, column {name}: {value} is not a finite "
                                              "number")
            _check_row(self.source, f"row {row + 1}", values)
        if not np.any(self.weight > 0):
            raise IdentificationError(f"{self.source}: every row has weight 0 (or there are no rows); give at least "
                                      "one row a weight > 0")

    @property
    def name(self) -> str:
        return Path(self.source).name

    def __len__(self) -> int:
        return self.amplitude_mm.size

    @classmethod
    def from_characterisation(cls, table, source: str = "computed table") -> "KdynTable":
        """The rows of a ``dynamic_stiffness.DynamicStiffness``, weight 1."""
        return cls(table.amplitude_mm.copy(), table.frequency_hz.copy(), table.preload_mm.copy(),
                   table.kdyn_N_per_mm.copy(), table.loss_angle_deg.copy(), np.ones(len(table)), source)

    def subset(self, rows: np.ndarray) -> "KdynTable":
        """The rows selected by the boolean mask ``rows`` (contiguous arrays)."""
        return KdynTable(*(np.ascontiguousarray(getattr(self, name)[rows]) for name in COLUMNS), self.source,
                         None if self.temperature_K is None else np.ascontiguousarray(self.temperature_K[rows]))

    def kept(self) -> "KdynTable":
        """The rows of weight > 0."""
        return self.subset(self.weight > 0)

    def with_values(self, kdyn_N_per_mm, loss_angle_deg, source: str | None = None) -> "KdynTable":
        return KdynTable(self.amplitude_mm, self.frequency_hz, self.preload_mm, np.asarray(kdyn_N_per_mm, float),
                         np.asarray(loss_angle_deg, float), self.weight, source or self.source, self.temperature_K)

    def temperature_groups(self) -> list[tuple[tuple[tuple[str, float], ...], np.ndarray]]:
        """(the rows' conditions, their indices) of each temperature the table holds, in the order
        they first appear (``DrivenInput.conditions``); one group of every row and no conditions
        where it has no temperature column."""
        if self.temperature_K is None:
            return [((), np.arange(len(self)))]
        temperatures = list(dict.fromkeys(float(t) for t in self.temperature_K))
        return [((("temperature_K", t),), np.flatnonzero(self.temperature_K == t)) for t in temperatures]


def load_kdyn_table(path: str | Path) -> KdynTable:
    """Read and check a table (see the module docstring), such as ``write_kdyn_table`` writes.
    IdentificationError names the line and column of what is wrong: a missing column, a value
    that is not a number, an amplitude or frequency <= 0, |K*| <= 0, a loss angle outside 0-90
    deg, a negative weight, a case (amplitude, frequency, preload) given twice. Warns
    (CharacterisationWarning) about an amplitude above 50 mm or a frequency above 500 Hz (a unit
    mistake, most likely)."""
    path = Path(path)
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:   # -sig: a spreadsheet's BOM
            lines = [(number, line) for number, line in enumerate(handle, start=1)
                     if line.strip() and not line.lstrip().startswith("#")]
    except FileNotFoundError:
        raise IdentificationError(f"dynamic-stiffness table {path} does not exist") from None
    except UnicodeDecodeError as exc:
        raise IdentificationError(f"{path}: not a text CSV file ({exc})") from None
    if not lines:
        raise IdentificationError(f"{path}: no header and no rows")
    header = [name.strip() for name in next(csv.reader([lines[0][1]]))]
    repeated = sorted({name for name in header if header.count(name) > 1})
    if repeated:
        raise IdentificationError(f"{path}, line {lines[0][0]}: the column(s) {', '.join(repeated)} appear more than once")
    missing = [name for name in REQUIRED if name not in header]
    if missing:
        raise IdentificationError(f"{path}: missing column(s) {', '.join(missing)}; a table needs "
                                  f"{','.join(REQUIRED)} (optional: {', '.join(OPTIONAL)}), found {','.join(header)}")
    if len(lines) < 2:
        raise IdentificationError(f"{path}: a header but no rows")
    columns = {name: [] for name in (*REQUIRED, *OPTIONAL)}
    temperature_column = temperature_column_of(path, header, lines[0][1])
    temperatures, temperature_lines = [], []
    seen: dict[tuple, int] = {}
    for number, line in lines[1:]:
        cells = [cell.strip() for cell in next(csv.reader([line]))]
        if len(cells) != len(header):
            raise IdentificationError(f"{path}, line {number}: {len(cells)} values for {len(header)} columns")
        row = dict(zip(header, cells))
        values = {}
        for name in columns:
            text = row.get(name, "")
            if name in OPTIONAL and text == "":
                values[name] = OPTIONAL[name]
                continue
            try:
                values[name] = float(text)
            except ValueError:
                raise IdentificationError(f"{path}, line {number}, column {name}: {text!r} is not a number") from None
            if not math.isfinite(values[name]):
                raise IdentificationError(f"{path}, line {number}, column {name}: {text} is not a finite number")
        _check_row(path, f"line {number}", values)
        case = (values["amplitude_mm"], values["frequency_hz"], values["preload_mm"])
        if temperature_column is not None:
            name = header[temperature_column[0]]
            try:
                temperatures.append(float(row[name]))
            except ValueError:
                raise IdentificationError(f"{path}, line {number}, column {name}: {row[name]!r} is not a "
                                          "number") from None
            temperature_lines.append(number)
            case += (temperatures[-1],)
        if case in seen:
            at = f" at {case[3]:g} {temperature_column[1]}" if len(case) > 3 else ""
            raise IdentificationError(f"{path}, line {number}: the case {case[0]:g} mm, {case[1]:g} Hz, preload "
                                      f"{case[2]:g} mm{at} is given twice (also line {seen[case]})")
        seen[case] = number
        for name in columns:
            columns[name].append(values[name])
    temperature_K = None
    if temperature_column is not None:
        temperature_K = temperature_column_K(path, header[temperature_column[0]], temperature_column,
                                       np.array(temperatures), temperature_lines)
    table = KdynTable(*(np.array(columns[name]) for name in COLUMNS), source=str(path), temperature_K=temperature_K)
    for what, values, unit, plausible in (("amplitude", table.amplitude_mm, "mm", PLAUSIBLE_AMPLITUDE_MM),
                                          ("frequency", table.frequency_hz, "Hz", PLAUSIBLE_FREQUENCY_HZ)):
        if np.any(values > plausible):
            warnings.warn(f"{path}: {what} {float(np.max(values)):g} {unit} is above {plausible:g} {unit}, outside "
                          "what bushing tests use: check the unit", CharacterisationWarning, stacklevel=2)
    return table


def _check_row(path, where: str, values) -> None:
    """``where``: "line N" of a file or "row N" of a table made in Python."""
    for name, unit in (("amplitude_mm", "mm"), ("frequency_hz", "Hz"), ("kdyn_N_per_mm", "N/mm")):
        if values[name] <= 0:
            raise IdentificationError(f"{path}, {where}, column {name}: {values[name]:g} {unit}; it must be > 0")
    if not 0.0 <= values["loss_angle_deg"] <= 90.0:
        raise IdentificationError(f"{path}, {where}, column loss_angle_deg: {values['loss_angle_deg']:g} deg; "
                                  "a loss angle lies between 0 and 90 deg (a passive bushing)")
    if values["weight"] < 0:
        raise IdentificationError(f"{path}, {where}, column weight: {values['weight']:g}; give a weight >= 0")
