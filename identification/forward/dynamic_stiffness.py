"""Dynamic stiffness and loss angle: a parameter set described the way a bushing data sheet is.

For each case of a grid of amplitudes X [mm] and frequencies f [Hz] (about a preload P [mm]),
the bushing, relaxed at P, is driven by x = P + X*sin(2*pi*f*t) until its force is periodic
(criterion: ``identification.forward.steady_state``), and the first harmonic of the force over the
last cycle gives, as in ISO 4664-1's forced-vibration tests,

    K* = F1/X1 [N/mm],  |K*| the dynamic stiffness,  delta = arg K* the loss angle [deg],
    K' = |K*|*cos(delta) the storage stiffness,  K'' = |K*|*sin(delta) the loss stiffness,

plus the energy dissipated per cycle, the loop's area: the integral of F dx over the last cycle
(trapezoids between its samples) [N.mm = mJ]. Under a pure sine only the force's first
harmonic does work over a cycle, so the area equals pi*K''*X^2 for any periodic force, linear
or hysteretic (``energy_from_loss_stiffness_mJ`` gives it beside the area; the two are
computed independently, and their difference is quadrature error, about 1e-4 at 256 steps).
Peak force: the largest |F| over the last cycle [N], preload included.

Each sine runs ``steps_per_cycle`` communication steps per cycle on the compiled path (all cases
in parallel on every core). With the default 256 steps the input's secant path carries a first
harmonic (pi/N)^2/3 = 5e-5 smaller than the sine's, which bounds the accuracy of a linear
model's K* (tests/identification/forward/test_dynamic_stiffness.py checks the closed forms).

Units: mm, Hz, N/mm, degrees, mJ, N; parameters in the paper's N-mm-s units.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from fmu_src.model.registry import BushingModel, DEFAULT_MODEL
from identification.errors import CharacterisationWarning, IdentificationError
from identification.measured.kdyn_table import (PLAUSIBLE_AMPLITUDE_MM, PLAUSIBLE_FREQUENCY_HZ, SHEET_COLUMNS,
                                                SHEET_RESULT_COLUMNS, ensemble_columns, write_kdyn_table)

DEFAULT_AMPLITUDES_MM = (0.1, 0.5, 1.0, 2.0, 3.0)
DEFAULT_FREQUENCIES_HZ = (1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 50.0)
STEPS_PER_CYCLE = 256
MIN_CYCLES = 3
MAX_CYCLES = 2000
TOLERANCE = 1e-5
"""Steady state: the first harmonic changes by at most this (relative) from cycle to cycle, with
what a geometric approach has left (``identification.forward.steady_state``)."""
MAX_SUBSTEPS = 20000
COLUMNS = SHEET_COLUMNS
"""A table's columns, as its CSV file has them (``identification.measured.kdyn_table`` owns the file)."""
RESULT_COLUMNS = SHEET_RESULT_COLUMNS
"""The columns computed per case (the first three describe the case)."""

@dataclass
class DynamicStiffness:
    """One row per case (arrays of equal length, in COLUMNS' units) of the best parameter set;
    for an ensemble, ``minimum`` and ``maximum`` of each result column over its members."""
    amplitude_mm: np.ndarray
    frequency_hz: np.ndarray
    preload_mm: np.ndarray
    kdyn_N_per_mm: np.ndarray
    loss_angle_deg: np.ndarray
    storage_N_per_mm: np.ndarray
    loss_N_per_mm: np.ndarray
    energy_per_cycle_mJ: np.ndarray
    peak_force_N: np.ndarray
    cycles: np.ndarray                      # cycles simulated per case
    converged: np.ndarray                   # steady state reached per case
    loop_force_N: np.ndarray                # (cases, steps_per_cycle): the last cycle's force
    model: str = DEFAULT_MODEL
    title: str = ""                         # the model's title, for plots ("" : its name stands)
    members: int = 1
    minimum: dict[str, np.ndarray] = field(default_factory=dict)
    maximum: dict[str, np.ndarray] = field(default_factory=dict)

    def __len__(self) -> int:
        return self.amplitude_mm.size

    def column(self, name: str) -> np.ndarray:
        return getattr(self, name)

    @property
    def energy_from_loss_stiffness_mJ(self) -> np.ndarray:
        """pi*K''*X^2 [mJ]: the energy per cycle of a linear bushing with this loss stiffness."""
        return math.pi * self.loss_N_per_mm * self.amplitude_mm ** 2

    def loop_displacement_mm(self, case: int) -> np.ndarray:
        """The displacement at the samples of ``loop_force_N[case]``."""
        phase = 2.0 * math.pi * np.arange(self.loop_force_N.shape[1]) / self.loop_force_N.shape[1]
        return self.preload_mm[case] + self.amplitude_mm[case] * np.sin(phase)

    def to_csv(self, path: str | Path, comments: Sequence[str] = ()) -> Path:
        """COLUMNS, one row per case; an ensemble adds ``<column>_min``, ``<column>_max``;
        ``comments`` go first, as ``# `` lines. The file of ``kdyn_table.write_kdyn_table``:
        ``load_kdyn_table`` reads it back."""
        columns = {name: self.column(name) for name in COLUMNS}
        if self.minimum:
            columns.update(zip(ensemble_columns(RESULT_COLUMNS),
                               (table[name] for name in RESULT_COLUMNS for table in (self.minimum, self.maximum))))
        return write_kdyn_table(path, columns, comments)

    def summary(self) -> dict:
        """For ``--json``: the cases, their cycles and convergence, and how far the loop's area is
        from pi*K''*X^2 (0 for a linear model)."""
        energy_gap = self.energy_per_cycle_mJ - self.energy_from_loss_stiffness_mJ
        cases = []
        for i in range(len(self)):
            case = {name: float(self.column(name)[i]) for name in COLUMNS}
            case.update(cycles=int(self.cycles[i]), converged=bool(self.converged[i]),
                        energy_from_loss_stiffness_mJ=float(self.energy_from_loss_stiffness_mJ[i]))
            if self.minimum:
                case["ensemble"] = {name: [float(self.minimum[name][i]), float(self.maximum[name][i])]
                                    for name in RESULT_COLUMNS}
            cases.append(case)
        relative = np.abs(energy_gap) / np.maximum(np.abs(self.energy_per_cycle_mJ), 1e-300)
        return {"model": self.model, "members": self.members, "cases": cases,
                "all_converged": bool(np.all(self.converged)),
                "largest_energy_difference_relative": float(np.max(relative))}

    def format(self) -> str:
        lines = [f"{'X mm':>6} {'f Hz':>7} {'|K*| N/mm':>10} {'delta deg':>9} {'K` N/mm':>9} {'K`` N/mm':>9} "
                 f"{'E mJ':>9} {'peak N':>8} {'cycles':>6}"]
        for i in range(len(self)):
            lines.append(f"{self.amplitude_mm[i]:6.3g} {self.frequency_hz[i]:7.4g} {self.kdyn_N_per_mm[i]:10.1f} "
                         f"{self.loss_angle_deg[i]:9.2f} {self.storage_N_per_mm[i]:9.1f} {self.loss_N_per_mm[i]:9.1f} "
                         f"{self.energy_per_cycle_mJ[i]:9.4g} {self.peak_force_N[i]:8.1f} {int(self.cycles[i]):6d}"
                         + ("" if self.converged[i] else "  not steady"))
        return "\n".join(lines)


@dataclass(frozen=True)
class SteadyStateLoop:
    """How each sine runs to its steady state (``steady_state``): ``steps_per_cycle`` integration
    steps per cycle; until the relative change of |K*| between cycles is below ``tolerance`` (0:
    exactly ``max_cycles`` cycles, a smooth function of the parameters, as a fit needs), at most
    ``max_cycles`` (one cap, or one per case); ``max_substeps`` per step before a case fails."""
    steps_per_cycle: int = STEPS_PER_CYCLE
    max_cycles: Any = MAX_CYCLES
    tolerance: float = TOLERANCE
    max_substeps: int = MAX_SUBSTEPS


def characterise(parameters, amplitudes_mm: Sequence[float] = DEFAULT_AMPLITUDES_MM,
                 frequencies_hz: Sequence[float] = DEFAULT_FREQUENCIES_HZ, model: str | BushingModel | None = None,
                 preload_mm: float = 0.0, **loop) -> DynamicStiffness:
    """Dynamic stiffness |K*| and loss angle on every pair of amplitudes and frequencies: the
    data sheet a supplier gives.

    Parameters
    ----------
    parameters : mapping, ParameterSet, ParameterEnsemble, FitResult, str or Path
        A set or an ensemble (paper's N-mm-s units), in any form ``parameter_sets`` accepts;
        an ensemble adds the members' min/max.
    amplitudes_mm : sequence of float
        Sine amplitudes [mm].
    frequencies_hz : sequence of float
        Frequencies [Hz].
    model : str or BushingModel, optional
        The model the parameters must be for (or its name).
    preload_mm : float
        Static displacement [mm] the sines are about.

    Other Parameters
    ----------------
    steps_per_cycle : int
        Integration steps per cycle (>= 16).
    tolerance : float
        Relative change of |K*| between cycles that counts as the steady state.
    max_cycles : int
        Cycle cap per case.

    Returns
    -------
    DynamicStiffness
        Per case (amplitude-major): |K*| [N/mm], loss angle [deg], K', K'' and, for an
        ensemble, their min/max; ``to_csv``, ``format`` and ``summary``.

    Raises
    ------
    IdentificationError
        Invalid grid values or a simulation that fails.
    TypeError
        A keyword that is not a loop setting (``SteadyStateLoop``).

    Warns
    -----
    CharacterisationWarning
        A case that reaches ``max_cycles`` without a steady state.
    """
    # here, not at the top: the command line imports this module for its defaults
    from identification.forward.parameter_sets import parameter_sets
    loop = SteadyStateLoop(**loop)
    bushing, sets = parameter_sets(parameters, model)
    return data_sheet(bushing, sets, amplitudes_mm, frequencies_hz, preload_mm, loop, stacklevel=3)


def characterise_at_temperatures(parameters, temperatures_K: Sequence[float],
                                 amplitudes_mm: Sequence[float] = DEFAULT_AMPLITUDES_MM,
                                 frequencies_hz: Sequence[float] = DEFAULT_FREQUENCIES_HZ,
                                 preload_mm: float = 0.0) -> list[tuple[float, DynamicStiffness]]:
    """:func:`characterise` at each of ``temperatures_K`` [K] of a model with a temperature law
    (``BushingModel.conditions``: every set's ``temperature`` set to each in turn), as
    (temperature, table) pairs: the data sheet over temperature. IdentificationError for a model
    without a law, or a temperature its law refuses (named, with its unit and range)."""
    from fmu_src.model.parameter_specs import ParameterError
    from identification.forward.parameter_sets import parameter_sets
    from identification.forward.population import conditioned_set
    bushing, sets = parameter_sets(parameters, None)
    if not any(field == "temperature_K" for _, field in bushing.conditions):
        raise IdentificationError(f"the {bushing.name} model has no temperature law: its data sheet is the same at "
                                  "every temperature (fit it with the option wlf or arrhenius)")
    out = []
    for temperature in temperatures_K:
        at = [conditioned_set(bushing, values, (("temperature_K", float(temperature)),)) for values in sets]
        try:
            at = [bushing.check(values) for values in at]
        except ParameterError as exc:
            raise IdentificationError(f"{float(temperature) - 273.15:g} degC: {exc}") from None
        out.append((float(temperature), data_sheet(bushing, at, amplitudes_mm, frequencies_hz, preload_mm,
                                                   SteadyStateLoop(), stacklevel=3)))
    return out


def write_temperature_sheet(path: str | Path, tables: Sequence[tuple[float, DynamicStiffness]],
                            comments: Sequence[str] = ()) -> Path:
    """The tables of :func:`characterise_at_temperatures` as one data sheet with a ``temperature_K``
    column [K] (``kdyn_table.load_kdyn_table`` reads it back: a table to fit across temperatures)."""
    columns: dict[str, list[np.ndarray]] = {}
    for temperature, table in tables:
        for name in COLUMNS:
            columns.setdefault(name, []).append(table.column(name))
        columns.setdefault("temperature_K", []).append(np.full(len(table), temperature))
    return write_kdyn_table(path, {name: np.concatenate(parts) for name, parts in columns.items()}, comments)


def data_sheet(bushing: BushingModel, sets: list[dict[str, float]], amplitudes_mm: Sequence[float],
               frequencies_hz: Sequence[float], preload_mm: float, loop: SteadyStateLoop,
               stacklevel: int = 2) -> DynamicStiffness:
    """``characterise`` of parameter sets already read and checked (``parameter_sets``): the
    model, its sets (paper's N-mm-s units, best first), the grid [mm], [Hz], the preload [mm]
    and the loop's settings. For a caller that holds them, such as a fit. ``stacklevel``: the
    frame its warnings name, as ``warnings.warn`` counts (2: the caller)."""
    from identification.forward.population import parameter_matrix
    amplitudes = _grid_values(amplitudes_mm, "amplitude", "mm", PLAUSIBLE_AMPLITUDE_MM, stacklevel + 1)
    frequencies = _grid_values(frequencies_hz, "frequency", "Hz", PLAUSIBLE_FREQUENCY_HZ, stacklevel + 1)
    _check_loop(preload_mm, loop)
    loop = SteadyStateLoop(int(loop.steps_per_cycle), int(loop.max_cycles), loop.tolerance, loop.max_substeps)
    case_amplitude = np.repeat(amplitudes, frequencies.size)
    case_frequency = np.tile(frequencies, amplitudes.size)
    cases = case_amplitude.size
    members = len(sets)
    result, last = run_sines(parameter_matrix(sets, bushing), bushing, case_amplitude, case_frequency,
                             np.full(cases, float(preload_mm)), loop)
    failed = (result[:, 3] == 2) | ~np.all(np.isfinite(last), axis=1)
    if failed[:cases].any():
        i = int(np.argmax(failed[:cases]))
        raise IdentificationError(f"the simulation of the {case_amplitude[i]:g} mm, {case_frequency[i]:g} Hz sine "
                                  "fails (overflow or too many substeps): check the units of the amplitude (mm) and "
                                  "the frequency (Hz)")
    runs = [k for k in range(members) if not failed[k * cases:(k + 1) * cases].any()]
    tables = [_table(result[k * cases:(k + 1) * cases], last[k * cases:(k + 1) * cases], case_amplitude,
                     case_frequency, float(preload_mm)) for k in runs]
    if len(runs) < members:
        warnings.warn(f"{members - len(runs)} of the {members} ensemble members fail on some case (overflow or too many "
                      "substeps) and are left out of the min/max columns", CharacterisationWarning, stacklevel=stacklevel)
    best = tables[0]
    _warn_unsteady(tables, case_amplitude, case_frequency, loop, stacklevel + 1)
    table = DynamicStiffness(case_amplitude, case_frequency, np.full(cases, float(preload_mm)),
                             **{name: best[name] for name in RESULT_COLUMNS}, cycles=best["cycles"],
                             converged=best["converged"], loop_force_N=best["loop"], model=bushing.name,
                             title=bushing.title, members=len(tables))
    if members > 1:
        table.minimum = {name: np.min([t[name] for t in tables], axis=0) for name in RESULT_COLUMNS}
        table.maximum = {name: np.max([t[name] for t in tables], axis=0) for name in RESULT_COLUMNS}
    return table


def _check_loop(preload_mm: float, loop: SteadyStateLoop) -> None:
    """``characterise``'s loop settings, each refused with its value and what is allowed."""
    steps_per_cycle, tolerance, max_cycles = loop.steps_per_cycle, loop.tolerance, loop.max_cycles
    if not math.isfinite(preload_mm):
        raise IdentificationError(f"preload = {preload_mm} mm: give a finite displacement")
    if int(steps_per_cycle) != steps_per_cycle or steps_per_cycle < 16:
        raise IdentificationError(f"steps_per_cycle = {steps_per_cycle}: give an integer >= 16")
    if not (0.0 < tolerance < 1.0):
        raise IdentificationError(f"tolerance = {tolerance}: give a relative change between 0 and 1")
    if int(max_cycles) != max_cycles or max_cycles < MIN_CYCLES:
        raise IdentificationError(f"max_cycles = {max_cycles}: give an integer >= {MIN_CYCLES}")


def _warn_unsteady(tables, case_amplitude, case_frequency, loop: SteadyStateLoop, stacklevel: int) -> None:
    """A CharacterisationWarning, at the frame ``stacklevel`` names, for the best set's cases and
    the ensemble members that reached no steady state within the loop's ``max_cycles``."""
    max_cycles, tolerance = loop.max_cycles, loop.tolerance
    not_steady = ~tables[0]["converged"]
    if not_steady.any():
        listed = ", ".join(f"{case_amplitude[i]:g} mm/{case_frequency[i]:g} Hz" for i in np.flatnonzero(not_steady))
        warnings.warn(f"no steady state within {max_cycles} cycles for {listed}: the first harmonic still changes by "
                      f"more than {tolerance:g} per cycle; these rows are the last cycle's (raise max_cycles)",
                      CharacterisationWarning, stacklevel=stacklevel)
    unsteady_members = sum(not t["converged"].all() for t in tables[1:])
    if unsteady_members:
        warnings.warn(f"{unsteady_members} ensemble member(s) reach no steady state within {max_cycles} cycles on some "
                      "case; their last cycle is in the min/max columns", CharacterisationWarning,
                      stacklevel=stacklevel)


def run_sines(matrix: np.ndarray, model: str | BushingModel, amplitude_mm: np.ndarray, frequency_hz: np.ndarray,
              preload_mm: np.ndarray, loop: SteadyStateLoop = SteadyStateLoop()):
    """Every parameter set (rows of ``matrix``) on every case (equal-length arrays), run as
    ``loop`` says: the compiled loop of ``identification.forward.steady_state``, cases of all
    sets in parallel. Returns its ``result`` (P*cases, 4: a, b, cycles, status; set-major) and
    ``last`` (P*cases, steps). Status 1: no steady state within the cycles (with tolerance 0:
    done); 2: the case failed (too many substeps)."""
    from identification.forward.population import compiled_model
    steps_per_cycle, tolerance = loop.steps_per_cycle, loop.tolerance
    members, cases = matrix.shape[0], amplitude_mm.size
    cycles = np.broadcast_to(np.asarray(loop.max_cycles, dtype=np.int64), (cases,))
    rows = np.repeat(np.arange(members, dtype=np.int64), cases)
    result = np.zeros((rows.size, 4))
    last = np.zeros((rows.size, steps_per_cycle))
    compiled_model(model)._sine_steady_state(
        matrix, rows, np.tile(amplitude_mm, members), np.tile(frequency_hz, members), np.tile(preload_mm, members),
        steps_per_cycle, min(MIN_CYCLES, int(cycles.min())), np.tile(cycles, members), tolerance, loop.max_substeps,
        result, last)
    return result, last


def run_table_rows(matrix: np.ndarray, model: BushingModel, rows, loop: SteadyStateLoop) -> np.ndarray:
    """:func:`run_sines` on the rows of a ``kdyn_table.KdynTable`` (their amplitudes, frequencies,
    preloads; ``loop.max_cycles`` one cap or one per row), each row at its own temperature where
    the table has one (``KdynTable.temperature_groups``: the matrix's condition columns set,
    ``population.conditioned``). Returns ``result`` (P, rows, 4)."""
    from identification.forward.population import conditioned
    cycles = np.broadcast_to(np.asarray(loop.max_cycles, dtype=np.int64), (len(rows),))
    result = np.empty((matrix.shape[0], len(rows), 4))
    for conditions, index in rows.temperature_groups():
        part, _ = run_sines(conditioned(matrix, model, conditions), model, rows.amplitude_mm[index],
                            rows.frequency_hz[index], rows.preload_mm[index],
                            SteadyStateLoop(loop.steps_per_cycle, cycles[index], loop.tolerance, loop.max_substeps))
        result[:, index] = part.reshape(matrix.shape[0], index.size, 4)
    return result


def stiffness_from_sums(result: np.ndarray, amplitude_mm: np.ndarray) -> tuple[np.ndarray, ...]:
    """(K', K'', |K*|, delta) [N/mm, N/mm, N/mm, deg] from the kernel's first-harmonic sums
    (``result[..., 0]`` = a, ``result[..., 1]`` = b of ``identification.forward.steady_state``):
    K* = (b + i*a)/X."""
    storage = result[..., 1] / amplitude_mm
    loss = result[..., 0] / amplitude_mm
    return storage, loss, np.hypot(storage, loss), np.degrees(np.arctan2(loss, storage))


def _table(result: np.ndarray, last: np.ndarray, amplitude: np.ndarray, frequency: np.ndarray, preload: float) -> dict:
    """The result columns of one parameter set from the kernel's first-harmonic sums and last cycles."""
    storage, loss, kdyn, angle = stiffness_from_sums(result, amplitude)
    steps = last.shape[1]
    x = preload + amplitude[:, None] * np.sin(2.0 * math.pi * np.arange(steps) / steps)[None, :]
    # the closed loop's area by trapezoids, the last sample joined to the first
    energy = np.sum(0.5 * (last + np.roll(last, -1, axis=1)) * (np.roll(x, -1, axis=1) - x), axis=1)
    return {"kdyn_N_per_mm": kdyn, "loss_angle_deg": angle,
            "storage_N_per_mm": storage, "loss_N_per_mm": loss, "energy_per_cycle_mJ": energy,
            "peak_force_N": np.max(np.abs(last), axis=1), "cycles": result[:, 2].astype(int),
            "converged": result[:, 3] == 0, "loop": last.copy()}


def _grid_values(values, what: str, unit: str, plausible: float, stacklevel: int) -> np.ndarray:
    array = np.atleast_1d(np.asarray(values, dtype=float))
    if array.ndim != 1 or array.size == 0:
        raise IdentificationError(f"give at least one {what} [{unit}]")
    for value in array:
        if not (math.isfinite(value) and value > 0.0):
            raise IdentificationError(f"{what} = {value} {unit}: give a finite value > 0")
    if len(set(array.tolist())) != array.size:
        raise IdentificationError(f"{what}s {array.tolist()} {unit}: a value is repeated")
    if np.any(array > plausible):
        warnings.warn(f"{what} {float(np.max(array)):g} {unit} is above {plausible:g} {unit}, outside what bushing "
                      "tests use: check the unit", CharacterisationWarning, stacklevel=stacklevel)
    return array
