"""Read and write measured bushing tests (CSV).

Format: optional comment lines starting with ``#`` (provenance; synthetic files say so
there), then a header naming columns with their units, then comma-separated numbers:

    time_s,displacement_mm,force_N[,velocity_mm_s][,temperature_K]

A file whose name ends in ``.gz`` (``test.csv.gz``) is read through gzip, as numpy and pandas do.

Other declared units are converted: displacement in m, mm, in; force in N, kN, lbf, kip;
velocity in m_s, mm_s, in_s (per second); temperature in K or C (the rubber's, constant or
varying). Internal units: s, mm, N, mm/s, K. A temperature at or below absolute zero is refused;
one outside PLAUSIBLE_TEMPERATURE_K (a Fahrenheit column read as Celsius, Celsius as kelvin) warns.

When the velocity is absent it is derived from the displacement with second-order finite
differences (``numpy.gradient``: central in the interior, one-sided at both ends), which
amplifies displacement noise by about 1/(sqrt(2)*dt).

Plausibility. A file in the wrong units loads without error, so :func:`plausibility_warnings`
checks what a rubber-bushing test can look like and warns (``MeasurementWarning``), naming the
column, what it found and the likely mistake: peak displacement outside PLAUSIBLE_PEAK_DISPLACEMENT_MM
(metres or micrometres in a millimetre column), peak force below MIN_PLAUSIBLE_FORCE_N (kN in
a newton column), a secant stiffness (force range over displacement range) outside
PLAUSIBLE_STIFFNESS_N_PER_MM, a sample rate outside PLAUSIBLE_SAMPLE_RATE_HZ (time in ms), and a
displacement that moves more than half its rms between samples (sampled too slowly for its
content, or a wrong time unit).
"""
from __future__ import annotations

import gzip
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from identification.errors import MeasurementError, MeasurementWarning  # noqa: F401  (also imported from here)

LENGTH_TO_MM = {"mm": 1.0, "m": 1000.0, "in": 25.4}
FORCE_TO_N = {"N": 1.0, "kN": 1000.0, "lbf": 4.4482216152605, "kip": 4448.2216152605}
VELOCITY_TO_MM_S = {"mm_s": 1.0, "m_s": 1000.0, "in_s": 25.4}
MIN_SAMPLES = 10
PLAUSIBLE_PEAK_DISPLACEMENT_MM = (0.01, 200.0)
MIN_PLAUSIBLE_FORCE_N = 10.0
PLAUSIBLE_STIFFNESS_N_PER_MM = (1.0, 1e6)
PLAUSIBLE_SAMPLE_RATE_HZ = (10.0, 1e6)
MAX_STEP_OVER_RMS = 0.5
TEMPERATURE_TO_K = {"K": (1.0, 0.0), "C": (1.0, 273.15)}
"""(factor, offset) of each temperature unit: T [K] = factor * value + offset."""
PLAUSIBLE_TEMPERATURE_K = (173.15, 473.15)
"""-100 to +200 degC: what a rubber test's temperature can be."""


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
    temperature_K: np.ndarray | None = None     # the rubber's temperature [K] at each sample, if the file has it

    def __len__(self) -> int:
        return self.time_s.size

    @property
    def conditions(self) -> tuple[tuple[str, float], ...]:
        """(field, value) of the test's conditions a model may take (``BushingModel.conditions``):
        ``temperature_K``, the mean of its temperature column [K], where it has one."""
        if self.temperature_K is None:
            return ()
        return (("temperature_K", self.mean_temperature_K),)

    @property
    def mean_temperature_K(self) -> float:
        """The mean of its temperature column [K]; NaN where it has none."""
        return math.nan if self.temperature_K is None else float(np.mean(self.temperature_K))

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


def _read_text(path: Path) -> str:
    """The text of a CSV, or of a gzip-compressed one if its name ends in ``.gz``."""
    compressed = path.suffix.lower() == ".gz"
    try:
        if compressed:
            with gzip.open(path, "rt", encoding="utf-8") as stream:
                return stream.read()
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MeasurementError(f"measurement file {path} does not exist") from None
    except IsADirectoryError:
        raise MeasurementError(f"measurement file {path} is a directory") from None
    except (gzip.BadGzipFile, EOFError) as exc:
        raise MeasurementError(f"{path}: not a readable gzip file ({exc}); "
                               "only a compressed CSV may end in .gz") from None
    except UnicodeDecodeError as exc:
        hint = "" if compressed else "; a compressed file must end in .gz"
        raise MeasurementError(f"{path}: not UTF-8 text (byte {exc.start}){hint}") from None


def measurement_name(source: str | Path) -> str:
    """A measurement file's name without its directory and its ``.csv`` / ``.csv.gz`` suffixes,
    for the names of the plots and tables made from it."""
    name = Path(source).name
    for suffix in (".gz", ".csv"):
        if name.lower().endswith(suffix):
            name = name[: -len(suffix)]
    return name


def temperature_column_of(path: Path, names: list[str], header: str) -> tuple[int, str] | None:
    """(index, unit) of the header's temperature column, or None; MeasurementError for two or
    an unknown unit."""
    found = [i for i, name in enumerate(names) if name.split("_")[0] == "temperature"]
    if len(found) > 1:
        raise MeasurementError(f"{path}: more than one temperature column in header {header!r}")
    if not found:
        return None
    unit = names[found[0]][len("temperature_"):]
    if unit not in TEMPERATURE_TO_K:
        raise MeasurementError(f"{path}: column {names[found[0]]!r} has unknown unit {unit!r}; "
                               f"allowed: {', '.join(f'temperature_{u}' for u in TEMPERATURE_TO_K)}")
    return found[0], unit


def temperature_column_K(path: Path, name: str, column: tuple[int, str], values: np.ndarray,
                         lines: list[int]) -> np.ndarray:
    """The column's temperatures [K] (``lines`` the file's line of each sample); refused at or below
    absolute zero, warned outside PLAUSIBLE_TEMPERATURE_K."""
    unit = column[1]
    factor, offset = TEMPERATURE_TO_K[unit]
    temperature = values * factor + offset
    cold = np.flatnonzero(temperature <= 0.0)
    if cold.size:
        raise MeasurementError(f"{path}, line {lines[int(cold[0])]}: {name} = {values[int(cold[0])]:g} [{unit}] is at "
                               "or below absolute zero; give the rubber's temperature in K or C")
    low, high = PLAUSIBLE_TEMPERATURE_K
    if np.min(temperature) < low or np.max(temperature) > high:
        warnings.warn(f"{path}: column {name}: {np.min(temperature) - 273.15:.4g} to "
                      f"{np.max(temperature) - 273.15:.4g} degC is outside a rubber test's {low - 273.15:g} to "
                      f"{high - 273.15:g} degC; Fahrenheit read as Celsius, or Celsius as kelvin?",
                      MeasurementWarning, stacklevel=3)
    return temperature


def load_measurement(path: str | Path, force_optional: bool = False) -> Measurement:
    """Load a measured (or synthetic) rig test from a CSV file.

    Parameters
    ----------
    path : str or Path
        CSV with a header line naming ``time_s``, ``displacement_<unit>`` (mm, m, in),
        ``force_<unit>`` (N, kN, lbf, kip) and optionally ``velocity_<unit>`` columns; ``#``
        lines are comments. A name ending in ``.gz`` is read as a gzip-compressed CSV.
    force_optional : bool
        Accept a file without a force column (an input to ``predict``).

    Returns
    -------
    Measurement
        Time [s], displacement [mm], force [N] and, if given, velocity [mm/s], converted from
        the file's units.

    Raises
    ------
    MeasurementError
        Naming what is wrong and where (file, line, column).
    """
    path = Path(path)
    lines = _read_text(path).splitlines()
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

    temperature_column = temperature_column_of(path, names, header)

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
    headers = {quantity: names[index] for quantity, (index, _) in columns.items()}
    for message in plausibility_warnings(time_s, displacement, force if has_force else None, headers):
        warnings.warn(f"{path}: {message}", MeasurementWarning, stacklevel=2)
    temperature = None
    if temperature_column is not None:
        temperature = temperature_column_K(path, names[temperature_column[0]], temperature_column,
                                     data[:, temperature_column[0]], [number for number, _ in rows])
    return Measurement(time_s, displacement, force, velocity, derived, str(path), comments, has_force, temperature)


def plausibility_warnings(time_s, displacement_mm, force_N=None, headers=None) -> list[str]:
    """What looks wrong for a rubber-bushing test (see the module docstring), each naming the
    column, what was found and the likely mistake; [] if nothing does."""
    headers = {"time": "time_s", "displacement": "displacement_mm", "force": "force_N", **(headers or {})}
    found = []
    peak = float(np.max(np.abs(displacement_mm)))
    low, high = PLAUSIBLE_PEAK_DISPLACEMENT_MM
    if peak < low:
        found.append(f"column {headers['displacement']}: peak displacement {peak:.3g} mm is below {low} mm; "
                     "metres in a millimetre column? (2 mm is 2, not 0.002)")
    elif peak > high:
        found.append(f"column {headers['displacement']}: peak displacement {peak:.3g} mm is above {high:g} mm, "
                     "beyond a bushing's travel; micrometres in a millimetre column?")
    if force_N is not None:
        peak_force = float(np.max(np.abs(force_N)))
        if peak_force < MIN_PLAUSIBLE_FORCE_N:
            found.append(f"column {headers['force']}: peak force {peak_force:.3g} N is below "
                         f"{MIN_PLAUSIBLE_FORCE_N:g} N; kilonewtons in a newton column?")
        travel = float(np.ptp(displacement_mm))
        if travel > 0 and peak_force > 0:
            stiffness = float(np.ptp(force_N)) / travel
            low, high = PLAUSIBLE_STIFFNESS_N_PER_MM
            if not low <= stiffness <= high:
                found.append(f"columns {headers['force']}/{headers['displacement']}: secant stiffness "
                             f"{stiffness:.3g} N/mm is outside {low:g}-{high:g} N/mm; check the units of both")
    interval = float(np.median(np.diff(time_s)))
    rate = 1.0 / interval
    low, high = PLAUSIBLE_SAMPLE_RATE_HZ
    if not low <= rate <= high:
        found.append(f"column {headers['time']}: sample interval {interval:.3g} s ({rate:.3g} Hz) is outside a "
                     f"rig's {low:g} Hz-{high:g} Hz; milliseconds in a seconds column?")
    moving = displacement_mm - np.mean(displacement_mm)
    spread = float(np.sqrt(np.mean(moving ** 2)))
    if spread > 0:
        step = float(np.sqrt(np.mean(np.diff(displacement_mm) ** 2)))
        if step > MAX_STEP_OVER_RMS * spread:
            found.append(f"column {headers['displacement']}: moves {step / spread:.2f} of its rms between samples "
                         f"({rate:.3g} Hz); sampled too slowly for its content, or a wrong time unit?")
    return found


def write_measurement(path: str | Path, time_s, displacement_mm, force_N, comments: list[str] = (),
                      temperature_K=None) -> None:
    """Write time_s,displacement_mm,force_N (and temperature_K [K], a number or one a sample, where
    given) with ``# `` comment lines first."""
    columns, names, formats = [time_s, displacement_mm, force_N], "time_s,displacement_mm,force_N", ["%.6f", "%.6f", "%.4f"]
    if temperature_K is not None:
        columns.append(np.broadcast_to(np.asarray(temperature_K, dtype=float), np.shape(time_s)))
        names, formats = names + ",temperature_K", formats + ["%.3f"]
    table = np.column_stack(columns)
    header = "".join(f"# {line}\n" for line in comments)
    with open(path, "w", encoding="utf-8") as stream:
        stream.write(header + names + "\n")
        np.savetxt(stream, table, delimiter=",", fmt=formats)
