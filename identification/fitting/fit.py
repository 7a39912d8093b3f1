"""Fit a model's parameters to training tests, and say how sure the fit is.

``fit(tests, model=DEFAULT_MODEL, preset="default", seed=0, workers=None, scheduler=None, ...)``:

1. the noise level of every test from its own data (``identification.measured.noise``);
2. the search (``identification.fitting.multistart``): screened Sobol starts (for a model with a
   spring and friction, some with those from the data's slowest loop:
   ``identification.fitting.loop_start``), then successive
   halving of bounded trust-region least squares on the misfit (``identification.fitting.objectives``),
   every start a task of the engine (``identification.fitting.engine``: this process, local worker
   processes, or a Dask cluster; the same seed gives the same bits on each);
3. the evidence (pyPESTO's multi-start practice, ``identification.fitting.result``): how many of the last stage's starts reach
   the best misfit within the ensemble threshold, and whether every training test is at its
   floor (NRMSE <= FLOOR_FACTOR x its noise level, or a sine's repeatability where that is larger). A fit that is not both is
   ``converged = False`` and says why (``FitResult.warning``);
4. how sure (``identification.fitting.ensemble``): the singular values of the residual Jacobian and
   the ensemble: distinct start end points and posterior draws (emcee) pushed to the edge of
   the 95 % confidence region.

The search itself is ``identification.fitting.search``. The ``paper`` preset replaces the Sobol screening by the paper's genetic algorithm (pymoo:
population 300, 200 generations, uniform crossover 0.8, mutation probability 0.05 per
coordinate) and keeps the rest. Kelvin-Voigt is fitted by linear least squares (the
optimum is exact, so only the floor is checked).
"""
from __future__ import annotations

import contextlib
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from fmu_src.model.registry import BushingModel, DEFAULT_MODEL, resolve_model
from fmu_src.parameter_files import ParameterSet
from identification.forward.population import parameter_matrix
from identification.fitting.engine import make_engine
from identification.errors import IdentificationError
from identification.extras import require
from identification.fitting.result import FitNotConvergedWarning, FitResult
from identification.measured.kdyn_table import KdynTable, load_kdyn_table
from identification.measured.measurements import Measurement
from identification.measured.multiaxis import COUPLED_AXES, MultiAxisMeasurement, coupled_axes, load_multiaxis
from identification.fitting.multistart import JACOBIANS
from identification.measured.noise import NoiseEstimate, estimate_noise
from identification.fitting.objectives import Objective
from identification.fitting.presets import FitOptions
from identification.fitting.presets import PRESETS, SearchSettings
from identification.measured.rig_tests import Manifest, RigTest
from identification.fitting.search_space import SearchSpace
from identification.fitting import search
from identification.fitting.search import MultiAxisTraining, SearchRequest, table_fit, test_fits

MIN_FINAL_STARTS = 3
"""A reduced budget (``starts``) keeps at least this many starts to the end: with two, one
stray start already makes the agreement fail."""


def as_tests(measurements) -> list[RigTest]:
    """RigTests from a Manifest, RigTests, Measurements (kind ``random``) or file paths."""
    from identification.measured.measurements import load_measurement
    if isinstance(measurements, Manifest):
        return list(measurements.tests)
    if isinstance(measurements, (RigTest, Measurement, str, Path)):
        measurements = [measurements]
    tests = []
    for item in measurements:
        if isinstance(item, RigTest):
            tests.append(item)
        elif isinstance(item, Measurement):
            tests.append(RigTest(item))
        else:
            tests.append(RigTest(load_measurement(item)))
    if not tests:
        raise IdentificationError("no training tests given")
    return tests


def as_multiaxis(multiaxis) -> list[MultiAxisMeasurement]:
    """MultiAxisMeasurements from MultiAxisMeasurements or file paths (``multiaxis.load_multiaxis``)."""
    if isinstance(multiaxis, (MultiAxisMeasurement, str, Path)):
        multiaxis = [multiaxis]
    return [m if isinstance(m, MultiAxisMeasurement) else load_multiaxis(m) for m in multiaxis or ()]


def fit(measurements, model: str | BushingModel = DEFAULT_MODEL, options: FitOptions | None = None,
        **keywords) -> FitResult:
    """Identify a model's parameters from rig tests, and say how sure the fit is.

    Parameters
    ----------
    measurements : Manifest, sequence of RigTest, Measurement, str or Path
        The training tests (``training_tests``, ``load_manifest``); a Measurement or a CSV path
        counts as a random-input test. May be empty when ``kdyn`` or ``multiaxis`` is given.
    model : str or BushingModel
        A model's name (``fmu_src.model.registry.MODEL_NAMES``; default ``DEFAULT_MODEL``, the
        paper's), or the model itself; resolved once and passed on. A model whose force is linear
        in its parameters (``BushingModel.linear``: Kelvin-Voigt) is fitted by linear least
        squares, every other by the search.
    options : FitOptions, optional
        The settings below as one value; keywords (``fit(tests, seed=1)``) are put into it.

    Other Parameters
    ----------------
    preset : str
        ``default`` (Sobol screening) or ``paper`` (the paper's GA); see ``presets``.
    seed : int
        Root seed (>= 0); the same seed gives the same bits on any engine.
    workers : int, optional
        Local worker processes (default: every core).
    scheduler : str or dask.distributed.Client, optional
        Run on a Dask cluster instead (the ``dask`` extra).
    engine : optional
        An engine to reuse (not closed).
    progress : bool
        Progress bars on stderr (drawn only where stderr is a terminal).
    screening, starts : int, optional
        Override the preset's Sobol points and first-stage starts (later stages shrink in
        proportion; at least ``MIN_FINAL_STARTS`` remain, or ``starts`` if fewer).
    kdyn : str, Path or KdynTable, optional
        A dynamic-stiffness table (CSV amplitude_mm, frequency_hz, kdyn_N_per_mm,
        loss_angle_deg) fitted with the tests, or alone.
    ensemble : bool
        False skips the profiles and the posterior sampling (a third to half of the time): no
        band then, and ``FitResult.save(ensemble=...)`` refuses.
    jacobian : str
        The residuals' Jacobian: ``exact`` (default: the forces' sensitivities,
        ``identification.forward.parameter_jacobian``) or ``difference`` (forward differences;
        the multi-axis tests' rows are differences either way).
    multiaxis : sequence of MultiAxisMeasurement, str or Path, optional
        Multi-axis tests (CSV time_s,dx_mm,dy_mm,Fx_N,Fy_N[,dz_mm,Fz_N]: ``identification.measured.multiaxis``)
        fitted with the one-axis tests, or alone: each axis's force at each sample a residual in
        that axis's noise units.
    coupling : str, optional
        How the model runs on the multi-axis tests (required with them): ``none`` (its one-axis
        model on each axis alone), ``radial`` (its coupled form on x and y, z alone) or
        ``spherical`` (on x, y and z). The fitted set is the one-axis set either way, which
        ``assemble --coupling`` turns into a six-axis file.
    fixed : mapping of str to float, optional
        Parameters held at these values (the model's units), not searched: a backbone's knots.

    Returns
    -------
    FitResult
        The best set with its provenance, each test's NRMSE against its noise level, the
        agreement of the starts, ``converged`` and, if not, ``warning``; ``summary()``,
        ``save()``.

    Raises
    ------
    IdentificationError
        No tests, a bad seed or preset, a test whose noise cannot be estimated, multi-axis tests
        without a coupling or with one they cannot carry (spherical on a plane test).
    MissingExtraError
        The ``fit`` extra is not installed.
    TypeError
        A keyword that is not a setting (its name).

    Warns
    -----
    FitNotConvergedWarning
        The fit is not at the noise floor or its starts do not agree (the message says which).

    Notes
    -----
    Units: time s, displacement mm, force N; parameters in the paper's N-mm-s units. With
    ``workers`` > 1, guard a script's top level with ``if __name__ == "__main__":``.
    """
    require("fit", "identification.fit")
    from threadpoolctl import threadpool_limits
    started = time.perf_counter()
    options = FitOptions.of(options, **keywords)
    request = training_request(measurements, model, options)
    # One BLAS thread here as in every task: a multi-threaded BLAS may sum in another order,
    # and the scales and the Jacobian's SVD computed here must not depend on the engine.
    with threadpool_limits(limits=1):
        result = fit_linear(request, started) if request.model.linear is not None else \
            _searched(request, options, started)
    if not result.converged:
        warnings.warn(result.warning, FitNotConvergedWarning, stacklevel=2)
    return result


def _searched(request: SearchRequest, options: FitOptions, started: float) -> FitResult:
    """The search's result on the engine ``options`` give or make. An engine made here is closed
    here, and aborted if the search is left by an exception (Ctrl-C, SIGTERM): see
    ``identification.fitting.engine``."""
    owned = options.engine is None
    engine = options.engine or make_engine(options.workers, options.scheduler)
    with engine if owned else contextlib.nullcontext():
        return search.run(request, engine, options.progress, started)


def training_request(measurements, model: str | BushingModel = DEFAULT_MODEL,
                     options: FitOptions | None = None, **keywords) -> SearchRequest:
    """``fit``'s arguments (the same names) read and checked: what one fit fits and how, for
    :func:`fit_linear` (a model whose force is linear in its parameters) or
    ``search.begin`` (every other; ``compare`` runs those step by step). Raises
    IdentificationError as ``fit`` does."""
    options = FitOptions.of(options, **keywords)
    tests, noise, table, multi, bushing = _training(measurements, model, options)
    if options.preset not in PRESETS:
        raise IdentificationError(f"unknown preset {options.preset!r}; choose one of {', '.join(PRESETS)}")
    settings = _settings(PRESETS[options.preset], options.screening, options.starts)
    return SearchRequest(tests, noise, bushing, options.preset, settings, options.seed, table, multi, options.jacobian,
                         options.ensemble, tuple(dict(options.fixed or {}).items()))


def _training(measurements, model, options: FitOptions):
    """``fit``'s arguments read and checked: (one-axis tests, their noise levels, the table or
    None, the multi-axis tests with their noise levels and coupling, the model)."""
    kdyn, coupling = options.kdyn, options.coupling
    table = kdyn if kdyn is None or isinstance(kdyn, KdynTable) else load_kdyn_table(kdyn)
    multi = as_multiaxis(options.multiaxis)
    _check_coupling(multi, coupling)
    empty = measurements is None or (isinstance(measurements, (list, tuple)) and not measurements)
    tests = [] if (empty and (table is not None or multi)) else as_tests(measurements)
    bushing = resolve_model(model)
    if options.seed < 0:
        raise IdentificationError(f"seed = {options.seed}: give an integer >= 0")
    if options.jacobian not in JACOBIANS:
        raise IdentificationError(f"jacobian = {options.jacobian!r}: choose one of {', '.join(JACOBIANS)}")
    noise = [_noise_of(t) for t in tests]
    multi = MultiAxisTraining(multi, [_axis_noise_of(m) for m in multi], coupling or "none")
    return tests, noise, table, multi, bushing


def _noise_of(test: RigTest) -> NoiseEstimate:
    try:
        return estimate_noise(test.measurement.force_N)
    except ValueError as exc:
        raise IdentificationError(f"{test.measurement.source}: {exc}") from None


def _axis_noise_of(m: MultiAxisMeasurement) -> list[NoiseEstimate]:
    try:
        return [estimate_noise(m.force_N[:, c]) for c in range(m.force_N.shape[1])]
    except ValueError as exc:
        raise IdentificationError(f"{m.source}: {exc}") from None


def _check_coupling(multi: list[MultiAxisMeasurement], coupling: str | None) -> None:
    """Multi-axis tests need a coupling they can carry; a coupling needs multi-axis tests."""
    if multi and coupling is None:
        raise IdentificationError(f"the multi-axis tests {', '.join(m.name for m in multi)} need a coupling: "
                                  f"{', '.join(COUPLED_AXES)} (--coupling)")
    if coupling is not None and not multi:
        raise IdentificationError(f"coupling {coupling!r} given without multi-axis tests: it says how the model runs "
                                  "on them (--multiaxis FILE)")
    for m in multi:
        coupled_axes(coupling, m)


def _settings(base: SearchSettings, screening: int | None, starts: int | None) -> SearchSettings:
    if starts is not None:
        if starts < 1:
            raise IdentificationError(f"starts = {starts}: give 1 or more")
        first = base.stages[0][0]
        stages = tuple((max(min(MIN_FINAL_STARTS, starts), round(count * starts / first)) if i else starts, evaluations)
                       for i, (count, evaluations) in enumerate(base.stages))
        base = replace(base, stages=stages)
    if screening is not None:
        base = replace(base, screening=screening)
    return base     # a preset's settings, or replace()'s, which validates them again


def linear_solution(bushing: BushingModel, measurements) -> dict[str, float]:
    """The parameters of a model whose force is linear in them (``bushing.linear``) by linear
    least squares on ``measurements`` (scipy's lsq_linear, within each parameter's range), the
    held ones at their values."""
    from scipy.optimize import lsq_linear
    names = [name for name, _ in bushing.linear.regressors]
    signal = {"displacement": "displacement_mm", "velocity": "velocity_mm_s"}
    design = np.column_stack([np.concatenate([getattr(m, signal[regressor]) for m in measurements])
                              for _, regressor in bushing.linear.regressors])
    force = np.concatenate([m.force_N for m in measurements])
    solution = lsq_linear(design, force, bounds=_ranges(bushing, names)).x
    return {**{name: float(value) for name, value in zip(names, solution)}, **dict(bushing.linear.held)}


def _ranges(bushing: BushingModel, names) -> tuple[list[float], list[float]]:
    """(lower, upper) bounds of the parameters ``names``: their allowed ranges (open ends +-inf)."""
    specs = {spec.name: spec for spec in bushing.specs}
    return ([-np.inf if specs[name].minimum is None else specs[name].minimum for name in names],
            [np.inf if specs[name].maximum is None else specs[name].maximum for name in names])


def fit_linear(request: SearchRequest, started: float) -> FitResult:
    """A model whose force is linear in its parameters (``request.model.linear``) by linear
    least squares (:func:`linear_solution`) on the tests other than steps (a linear spring cannot show
    the step's relaxation; all tests if there are only steps) and on every axis of the
    multi-axis tests (such a bushing couples nothing). With a dynamic-stiffness table: scipy's
    bounded least squares on the whole objective (tests and table), from that solution or, with
    a table alone, from the table's scales (k_ref for a stiffness, c_ref for a damping). Timed
    from ``started``."""
    from scipy.optimize import least_squares
    bushing, tests, noise, table, multi = request.model, request.tests, request.noise, request.table, request.multi
    free = [name for name, _ in bushing.linear.regressors]
    held = dict(bushing.linear.held)
    if tests or multi.measurements:
        values = linear_solution(bushing, ([t.measurement for t in tests if t.kind != "step"]
                                           or [t.measurement for t in tests]) + multi.components())
    else:
        scales = SearchSpace.from_table(table)
        scale = {"displacement": scales.k_ref, "velocity": scales.c_ref}
        values = {**{name: scale[regressor] for name, regressor in bushing.linear.regressors}, **held}
    objective = Objective(tests, noise, model=bushing, table=table, multiaxis=multi)
    if table is not None:
        def residuals(solved):
            return objective.residual_matrix(parameter_matrix([{**dict(zip(free, solved)), **held}], bushing))[0]
        solution = least_squares(residuals, [values[name] for name in free], bounds=_ranges(bushing, free),
                                 x_scale="jac")
        values = {**{name: float(value) for name, value in zip(free, solution.x)}, **held}
    parameters = ParameterSet(bushing, values)
    misfit = float(objective(parameter_matrix([values], bushing))[0])
    result = FitResult(parameters, misfit, test_fits(tests, noise, parameters) + multi.fits(parameters), [], 0.0,
                       [values], None, "linear", 0, 1, time.perf_counter() - started, table=table_fit(table, parameters),
                       residuals=objective.size, coupling=multi.coupling if multi.measurements else None)
    result.parameters.provenance = result.provenance()
    return result
