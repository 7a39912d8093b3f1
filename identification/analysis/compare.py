"""Choosing the model: fit several models on the same training tests, weigh them on what the user
has, and recommend one (the paper's comparison study, §3.1, §4.3, Figs. 15-17, made a decision).

The models race (``analysis.race``): each is screened, the ones that can still win are fitted to
the end (as ``fitting.fit`` fits them), and each fitted model is assessed on:

- training: its NRMSE against each test's floor (its noise level or, for a sine whose device
  repeats less than that, what it repeats from cycle to cycle:
  ``measured.repeatability``) and, where a dynamic-stiffness table is
  training data too (``training_table``, ``compare --kdyn``), the table's rms error in units of
  its uncertainty (at the floor: each within ``result.FLOOR_FACTOR`` of it), chi^2/n, and
  Schwarz's information criterion BIC = chi^2 + d*ln(n) over its d free parameters;
- held out: the validation files that are not training files (NRMSE and the paper's eq. 10), and
  a dynamic-stiffness table (|K*| and loss-angle errors per amplitude and frequency, and their
  rms in units of the table's uncertainty, ``kdyn_table``).

The recommendation (:func:`recommend`) is the simplest model that reaches the floor and
predicts best: among the models at the floor, those whose held-out errors are within
``PREDICTION_TOLERANCE`` of the best on each kind of held-out data (all of them, if none is held
out); of those the one with the fewest free parameters, then the lowest BIC. Where no model
reaches the floor, the fewest parameters says nothing (a linear bushing that misses the data by
140x its noise is not simpler than one that misses by 70x, it is worse): the models that predict
within the tolerance of the best (all, without held-out data), and of those the lowest BIC, with
a note that no model describes the data to their floor and by how much the chosen one misses.

Writes into the output directory: ``params_<model>.json`` per fitted model (with provenance; the
ensemble sampled for the recommended one), ``comparison.csv`` (one row per model: everything above
and whether it is the recommendation; for a model stopped after its screening, its screened and
first-stage chi^2/n and why it stopped),
``validation.csv`` (NRMSE and eq. 10 per file and model), ``kdyn_errors.csv`` (per row of the
table and model), one PNG per validation file (force over time and force-displacement loops) and
one for the table, each whole or not at all (``interrupt.writing``). Prints the tables; the last
line is ``recommended: <model>``.
"""
from __future__ import annotations

import csv
import math
import sys
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from fmu_src.model.registry import BushingModel, resolve_model
from identification.fitting.engine import make_engine
from identification.errors import FitNotConvergedWarning
from identification.fitting.result import (FLOOR_FACTOR, FitResult, TableFit, information_criterion,
                                           sines_repeatability)
from identification.fitting.fit import training_request
from identification.fitting.loop_start import FitStart
from identification.fitting.presets import FitOptions, from_a_fit
from identification.analysis.race import Stopped, race_models
from identification.fitting.search import table_fit
from identification.interrupt import writing
from identification.measured.kdyn_table import KDYN_UNCERTAINTY, LOSS_ANGLE_UNCERTAINTY_DEG, KdynTable
from identification.measured.measurements import load_measurement, measurement_name
from identification.fitting.objectives import nrmse, rms_level_error
from identification.analysis.plots import plot_comparison, plot_table_comparison
from identification.measured.rig_tests import RigTest
from identification.forward.simulate import simulate_record

PREDICTION_TOLERANCE = 0.1
"""A model predicts as well as the best if its held-out error is at most this much larger (10 %)."""


@dataclass
class Assessment:
    """One model on the comparison's data."""
    model: str
    free_parameters: int
    residuals: int
    misfit: float                          # chi^2/n over the training data (tests and a training table)
    training_ratio: float                  # the largest NRMSE over its floor of a training test (or table's error over its uncertainty)
    at_floor: bool
    converged: bool
    seconds: float
    floor: str = "the noise"                # what sets the worst training test's floor (RigTestFit.floor_words)
    screened_misfit: float | None = None    # the best chi^2/n of its screening (None: a linear model)
    first_stage_misfit: float | None = None  # the best chi^2/n after its first least-squares stage
    before_last_misfit: float | None = None  # the best chi^2/n after every stage but the last
    validation: dict[str, tuple[float, float]] = field(default_factory=dict)   # held-out file: (NRMSE, eq. 10)
    table: TableFit | None = None          # the held-out table at the fitted parameters

    @property
    def information_criterion(self) -> float:
        """BIC = chi^2 + d*ln(n) (``result.information_criterion``)."""
        return information_criterion(self.misfit, self.free_parameters, self.residuals)

    @property
    def validation_error(self) -> float | None:
        """The mean NRMSE over the held-out files (None without any)."""
        return float(np.mean([error for error, _ in self.validation.values()])) if self.validation else None

    @property
    def table_error(self) -> float | None:
        """The held-out table's rms error in units of its uncertainty (None without a table)."""
        return self.table.ratio if self.table is not None else None

    @classmethod
    def of(cls, result: FitResult) -> "Assessment":
        ratios = [t.ratio for t in result.tests] + ([result.table.ratio] if result.table is not None else [])
        worst = max(result.tests, key=lambda t: t.ratio, default=None)
        floor = worst.floor_words if worst is not None and worst.ratio == max(ratios) else "the noise"
        return cls(result.model, result.free_parameters, result.residuals, result.misfit,
                   max(ratios, default=math.nan), result.at_floor, result.converged, result.seconds, floor,
                   result.screened_misfit, result.first_stage_misfit, result.before_last_misfit)


@dataclass(frozen=True)
class Recommendation:
    model: str
    reason: str
    caveat: str = ""
    """Where no model reaches the floor: that none describes the data to their floor, the
    recommended model's miss (its worst training test against its noise level); else empty."""


def recommend(assessments: Sequence[Assessment], tolerance: float = PREDICTION_TOLERANCE) -> Recommendation:
    """The model to use (module docstring), why, and a caveat where none reaches the floor.

    Where some models reach the floor: of those, the ones that predict every kind of held-out
    data (files, then the table) within ``tolerance`` of the best; of those the one with the fewest
    free parameters, then the lowest BIC. Where none does, parsimony says nothing (every model misses
    the data): the ones that predict within ``tolerance`` of the best, where held-out data are given,
    and of those (of all, without) the lowest BIC, which weighs the fit itself against its
    parameters. A model whose fitted set fails on a whole training record (an infinite training
    ratio: the fit ran a stride or a prefix of it) is left out while another is not."""
    failed = [a for a in assessments if not math.isfinite(a.training_ratio)]
    if failed and len(failed) < len(assessments):    # a fitted set that fails on a whole training record
        assessments = [a for a in assessments if a not in failed]
    pool = [a for a in assessments if a.at_floor]
    why = [f"{len(pool)} of {len(assessments)} at the floor"]
    if not pool:
        pool = list(assessments)
        why = [f"no model reaches the floor (none of the {len(pool)} describes the data to their noise, or to what "
               "the device repeats)"]
    held_out = _predicting_best(pool, tolerance, why)
    filtered = len(held_out) < len(pool) or len(why) > 1
    if why[0].startswith("no model"):
        chosen = min(held_out, key=lambda a: (a.information_criterion, a.free_parameters))
        why.append(f"{chosen.model} has the lowest BIC{' of those' if filtered else ''}")
        caveat = (f"no model describes these data to their floor; the best, {chosen.model}, misses its worst "
                  f"training data by {chosen.training_ratio:.3g}x {chosen.floor} (or a training table's uncertainty; the floor "
                  f"is {FLOOR_FACTOR}x): treat "
                  "its predictions as approximate")
        return Recommendation(chosen.model, "; ".join(why), caveat)
    chosen = min(held_out, key=lambda a: (a.free_parameters, a.information_criterion))
    simplest = [a.model for a in held_out if a.free_parameters == chosen.free_parameters]
    why.append(f"{chosen.model} has the fewest free parameters of those ({chosen.free_parameters})"
               + (f" and the lowest BIC among {', '.join(simplest)}" if len(simplest) > 1 else ""))
    return Recommendation(chosen.model, "; ".join(why))


def _predicting_best(pool: list[Assessment], tolerance: float, why: list[str]) -> list[Assessment]:
    """Those of ``pool`` that predict each kind of held-out data they were assessed on (files, then
    the table) within ``tolerance`` of the best, saying so in ``why``; ``pool`` where none was held out."""
    for name, error in (("held-out files", lambda a: a.validation_error), ("table", lambda a: a.table_error)):
        known = [a for a in pool if error(a) is not None and math.isfinite(error(a))]
        if not known:
            continue
        best = min(error(a) for a in known)
        close = [a for a in known if error(a) <= (1.0 + tolerance) * best]
        why.append(f"{len(close)} predict the {name} within {tolerance:.0%} of the best")
        pool = close
    return pool


@dataclass(frozen=True)
class CompareOptions:
    """``compare_models``' settings (its keywords). The fits': ``preset``, ``seed``,
    ``screening``, ``starts``, ``fixed`` (parameters every model holds), ``training_table`` (a
    data sheet fitted with the tests, as ``fit(kdyn=...)``), ``workers``, ``scheduler``,
    ``progress`` (as ``fit``'s). The comparison's: ``ensemble`` (sample the recommended model's),
    ``every_ensemble`` (every finished model's), ``race`` (stop the models that cannot win after
    their screening), ``table`` (a held-out dynamic-stiffness table), ``multiaxis`` and
    ``couplings`` (held-out multi-axis tests and the couplings weighed on them)."""
    preset: str = "default"
    seed: int = 0
    screening: int | None = None
    starts: int | None = None
    fixed: Mapping[str, float] | None = None
    training_table: KdynTable | None = None
    workers: int | None = None
    scheduler: Any = None
    progress: bool = True
    ensemble: bool = True
    every_ensemble: bool = False
    race: bool = True
    table: KdynTable | None = None
    multiaxis: Any = ()
    couplings: Sequence[str] = ()
    fixed_by_model: Mapping[str, Mapping[str, float]] | None = None
    """Parameters a model holds, by the model's name, in place of ``fixed`` (a backbone read off a
    static test is pinned at 0 in a model with the rig's offsets, not in one without)."""
    alternatives: Mapping[str, Sequence[tuple[BushingModel, Mapping[str, float]]]] | None = None
    """By a model's name, the variants (model, the parameters it holds) it is weighed against if
    it is recommended: ``first_contact``'s options assumed, each left out in turn. They are fitted
    after the race and join it; the recommendation is made again over all."""
    first_contact: Any = None
    """What was assumed before the fits (``first_contact.FirstContact``): said in the summary."""
    leave_one_out: bool = False
    """Fit the recommended model again to the training tests but one, for each test, and predict
    that one (:class:`LeaveOneOut`): the matrix's leave-one-out score beside its training figures."""

    def training(self) -> FitOptions:
        """Each model's fit (its ensemble, if any, sampled later for the recommended one)."""
        return FitOptions(preset=self.preset, seed=self.seed, screening=self.screening, starts=self.starts,
                          fixed=self.fixed, kdyn=self.training_table, ensemble=False, workers=self.workers,
                          scheduler=self.scheduler, progress=self.progress)


def compare_models(models: Sequence[str | BushingModel], tests: Sequence[RigTest], validation_files: Sequence[Path],
                   out_dir: Path, **keywords) -> dict:
    """Fit every model on ``tests`` and the ``training_table`` (a data sheet, alone or with the
    tests, as ``fit(kdyn=...)``), assess it on the training data, on the ``validation_files``
    and on the held-out dynamic-stiffness ``table``, write the files (module docstring) and
    recommend one. ``models``: names or ``BushingModel``s, each resolved once here and passed on.
    The keywords are ``CompareOptions``' (``preset``, ``seed``, ``fixed`` … as ``fit``'s).

    The models race (:func:`race_models`): each is screened, and only those that can still win
    run the least-squares stages (``race=False``: every model runs them). The ensemble (profiles
    and posterior, ``ensemble``) is sampled for the recommended model, and for every finished
    one with ``every_ensemble``.

    Returns ``{"parameters": {model: params}, "errors": {(file, model): (nrmse, eq10)},
    "assessments": [Assessment], "recommendation": Recommendation, "stopped": [Stopped]}``
    (keyed by model name; a model stopped after its screening has no parameters, errors or
    assessment, only its row in ``stopped``)."""
    from threadpoolctl import threadpool_limits
    options = CompareOptions(**keywords)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    run = _Comparison([resolve_model(model) for model in models], list(tests),
                      [load_measurement(path) for path in validation_files], out_dir, options)
    # one BLAS thread, as fit() runs its searches
    with make_engine(options.workers, options.scheduler) as engine, warnings.catch_warnings(), \
            threadpool_limits(limits=1):
        warnings.simplefilter("ignore", FitNotConvergedWarning)   # reported below, per model
        run.fit(engine)
        if options.ensemble:
            run.sample_ensembles()
        left_out = None
        if options.leave_one_out and len(tests) >= 2:
            chosen = next(b for b in run.bushings if b.name == run.recommendation.model)
            left_out = leave_one_out(tests, run.results[chosen.name], lambda rest: run.request(chosen, tests=rest),
                                     engine, options.progress)
    return run.report(left_out)


class _Comparison:
    """One ``compare_models`` run: its models, tests and options, the fits as they are settled
    (written as they finish, :class:`_SettledWriter`), their assessments and the recommendation."""

    def __init__(self, bushings, tests, validation, out_dir: Path, options: CompareOptions):
        self.bushings, self.tests, self.validation, self.out_dir, self.options = bushings, tests, validation, out_dir, options
        self.training_names = {Path(t.measurement.source).name for t in tests}
        self.training = options.training()
        table = options.training_table
        self.data = [t.measurement.source for t in tests] + ([table.source] if table is not None else [])
        self.settled = _SettledWriter(out_dir, options.table, self.data)

    def request(self, bushing, fixed=None, tests=None, start: FitStart | None = None):
        """The search request of ``bushing`` (its held parameters ``fixed``, else the options'), on
        ``tests`` (default: every training test), from ``start`` (a nested model's fit) if given."""
        by_model = self.options.fixed_by_model or {}
        held = fixed if fixed is not None else by_model.get(bushing.name, self.options.fixed)
        request = training_request(self.tests if tests is None else tests, bushing, replace(self.training, fixed=held))
        return request if start is None else replace(request, start=start, settings=from_a_fit(request.settings))

    def fit(self, engine) -> None:
        """Race the models, assess them and recommend one; then race the recommended model's
        variants (``CompareOptions.alternatives``) and recommend again over all."""
        options, settled = self.options, self.settled
        self.engine = engine
        self.results, self.stopped, self.searches = race_models([self.request(b) for b in self.bushings], engine,
                                                                options.race, options.progress, settled)
        pending = options.alternatives or {}
        while True:
            self._assess()
            variants = [(b, f) for b, f in pending.get(self.recommendation.model, ()) if b.name not in self.results
                        and b.name not in {s.model for s in self.stopped}]
            pending = {}
            if not variants:
                return
            print(f"weighing {self.recommendation.model} against its variants (each option assumed left out, each "
                  f"option tried added): "
                  f"{', '.join(b.name for b, _ in variants)} ...", file=sys.stderr)
            results, stopped = self.results, self.stopped
            # each variant nests the recommended model or is nested in it: its fit is where to start
            fitted = dict(self.results[self.recommendation.model].parameters.parameters)
            more, more_stopped, more_searches = race_models([self.request(b, dict(f), start=FitStart(
                fitted, self.recommendation.model, dict(b.options.neutral if b.options else ())))
                for b, f in variants], engine,
                                                            False, options.progress,
                                                            lambda r, s: settled({**results, **r}, stopped + s))
            self.results.update(more)
            self.searches.update(more_searches)
            self.stopped = self.stopped + more_stopped
            self.bushings = self.bushings + [b for b, _ in variants]

    def _assess(self) -> None:
        self.bushings = [b for b in self.bushings if b.name in self.results]
        self.models = [b.name for b in self.bushings]
        self.parameters = {model: self.results[model].parameters.parameters for model in self.models}
        self.assessments = [self.settled.assessment(self.results[model]) for model in self.models]
        self.errors, self.predictions = _validation_errors(self.validation, self.bushings, self.parameters,
                                                           self.assessments, self.training_names)
        self.recommendation = recommend(self.assessments)

    def sample_ensembles(self) -> None:
        """The recommended model's ensemble (every finished model's with ``every_ensemble``): the
        best fit, the assessments and the recommendation stand."""
        for model in [m for m in self.models if m in self.searches and (self.options.every_ensemble
                                                                         or m == self.recommendation.model)]:
            print(f"sampling the ensemble of {model} (profiles, posterior) ...", file=sys.stderr)
            self.results[model] = self.searches[model].with_ensemble()
            self.results[model].save(self.out_dir / f"params_{model}.json", data=self.data)

    def report(self, left_out: "LeaveOneOut | None") -> dict:
        """The figures, the tables and the files (``compare_models``' module docstring); returns
        what ``compare_models`` does."""
        options, out_dir, recommendation = self.options, self.out_dir, self.recommendation
        table, validation, models, errors = options.table, self.validation, self.models, self.errors
        for m in validation:
            plot_comparison(m, self.predictions[Path(m.source).name],
                            out_dir / f"compare_{measurement_name(m.source)}.png")
        if table is not None:
            bushing_of = {b.name: b for b in self.bushings}
            plot_table_comparison(table, {bushing_of[a.model]: a.table for a in self.assessments},
                                  out_dir / f"compare_{table.name}.png")
        coupling = (weigh_couplings(self.parameters, self.bushings, options.multiaxis, options.couplings,
                                    recommendation.model) if options.couplings else None)
        if options.first_contact is not None:
            print(options.first_contact.format())
        print(format_assessments(self.assessments, recommendation, self.stopped))
        if validation:
            print(format_comparison(errors, models, [Path(m.source).name for m in validation], self.training_names))
            repeats = sines_repeatability(self.results[models[0]].tests) if models else None
            for line in general_excitation_lines(validation, errors, models, repeats):
                print(line)
        if table is not None:
            print(format_table_errors(table, self.assessments))
        if coupling is not None:
            print(coupling.format())
        _write_csvs(out_dir, self.assessments, recommendation, errors, table, self.stopped)
        if coupling is not None:
            coupling.write(out_dir / "coupling.csv")
        if left_out is not None:
            print(left_out.format())
            left_out.write(out_dir / "leave_one_out.csv")
        print(f"wrote {out_dir}/comparison.csv, validation.csv{', kdyn_errors.csv' if table is not None else ''}"
              f"{', coupling.csv' if coupling is not None else ''}{', leave_one_out.csv' if left_out else ''}, "
              "params_<model>.json and compare_*.png", file=sys.stderr)
        if recommendation.caveat:
            print(f"note: {recommendation.caveat}")
        if coupling is not None:
            print(f"recommended coupling: {coupling.chosen} ({coupling.reason})")
        print(f"why: {recommendation.reason}")
        print(f"recommended: {recommendation.model}")
        return {"parameters": self.parameters, "errors": errors, "assessments": self.assessments,
                "recommendation": recommendation, "coupling": coupling, "stopped": self.stopped,
                "leave_one_out": left_out}


@dataclass
class LeaveOneOut:
    """The recommended model on each training test: fitted to all (``training``), and fitted to
    the others and predicting it (``left_out``), NRMSE both, beside what the test repeats
    (``repeats``, a fraction of its rms force; None for a test without steady cycles, whose floor
    is its noise, ``noise``)."""
    model: str
    tests: list[str]
    training: list[float]
    left_out: list[float]
    repeats: list[float | None]
    noise: list[float]

    def floors(self) -> list[float]:
        return [r if r is not None and r > n else n for r, n in zip(self.repeats, self.noise)]

    def format(self) -> str:
        width = max([30] + [len(name) for name in self.tests])
        lines = [f"leave-one-out: {self.model} fitted to the training tests but one, predicting that one",
                 f"{'test':{width}s} {'training':>9s} {'left out':>9s} {'floor':>7s} {'training/floor':>15s} "
                 f"{'left out/floor':>15s}"]
        for name, trained, out, floor in zip(self.tests, self.training, self.left_out, self.floors()):
            lines.append(f"{name:{width}s} {trained:9.2%} {out:9.2%} {floor:7.2%} {trained / floor:15.2f} "
                         f"{out / floor:15.2f}")
        ratios = [out / floor for out, floor in zip(self.left_out, self.floors())]
        trained = [t / floor for t, floor in zip(self.training, self.floors())]
        lines.append(f"mean over the floor: training {np.mean(trained):.2f}x, left out {np.mean(ratios):.2f}x; "
                     f"worst: training {np.max(trained):.2f}x, left out {np.max(ratios):.2f}x (floor: what the test "
                     "repeats from cycle to cycle, or its noise where that is larger)")
        return "\n".join(lines)

    def write(self, path: Path) -> None:
        with writing(path) as temporary, open(temporary, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(["model", "test", "training_nrmse", "left_out_nrmse", "repeatability_fraction",
                             "noise_fraction", "floor_fraction"])
            for row in zip(self.tests, self.training, self.left_out, self.repeats, self.noise, self.floors()):
                name, trained, out, repeats, noise, floor = row
                writer.writerow([self.model, name, _cell(trained), _cell(out), _cell(repeats), _cell(noise),
                                 _cell(floor)])


def leave_one_out(tests: Sequence[RigTest], fitted: FitResult, request_of, engine, progress: bool) -> LeaveOneOut:
    """For each training test, the model of ``fitted`` fitted to the others (``request_of(tests)``,
    as the comparison fits, no ensemble) and simulated on it (from rest where it holds a force):
    :class:`LeaveOneOut`."""
    out = []
    for i, test in enumerate(tests):
        print(f"leave-one-out {i + 1}/{len(tests)}: {fitted.model} fitted without {test.name} ...", file=sys.stderr)
        rest = [t for j, t in enumerate(tests) if j != i]
        result = race_models([request_of(rest)], engine, False, progress)[0][fitted.model]
        m = test.measurement
        predicted = simulate_record(result.parameters, m)
        out.append(nrmse(predicted, m.force_N))
    by_name = {t.name: t for t in fitted.tests}
    return LeaveOneOut(fitted.model, [t.name for t in tests], [by_name[t.name].nrmse for t in tests], out,
                       [by_name[t.name].repeat_fraction for t in tests], [by_name[t.name].noise_fraction for t in tests])


def _assessed(result: FitResult, table: KdynTable | None) -> Assessment:
    assessment = Assessment.of(result)
    if table is not None:
        assessment.table = table_fit(table, result.parameters)
    return assessment


class _SettledWriter:
    """``race_models``' ``on_settled``: each model's parameter file as its fit finishes, and
    comparison.csv again with the rows so far (the recommendation column empty until the end), so
    that a crash, a signal or a full disk loses only the model in hand. Each model's assessment
    is made once, here, and kept for the final tables (:meth:`assessment`)."""

    def __init__(self, out_dir: Path, table: KdynTable | None, data: list[str]):
        self.out_dir, self.table, self.data = out_dir, table, data
        self.assessments: dict[str, Assessment] = {}

    def assessment(self, result: FitResult) -> Assessment:
        if result.model not in self.assessments:
            self.assessments[result.model] = _assessed(result, self.table)
        return self.assessments[result.model]

    def __call__(self, results: Mapping[str, FitResult], stopped: Sequence[Stopped]) -> None:
        for model, result in results.items():
            if model not in self.assessments:
                result.save(self.out_dir / f"params_{model}.json", data=self.data)
                self.assessment(result)
        _write_comparison(self.out_dir, list(self.assessments.values()), None, stopped)


def _validation_errors(validation, bushings, parameters: dict, assessments: list[Assessment], training_names: set):
    """Each model's (NRMSE, eq. 10) on each validation file, entered into its assessment where
    the file is held out; and the predictions, {file name: {model (the BushingModel): force [N]}}."""
    errors, predictions = {}, {}
    for m in validation:
        name = Path(m.source).name
        predicted_by_name = {bushing.name: simulate_record(parameters[bushing.name], m, model=bushing)
                             for bushing in bushings}
        predictions[name] = {bushing: predicted_by_name[bushing.name] for bushing in bushings}
        for assessment in assessments:
            predicted = predicted_by_name[assessment.model]
            errors[name, assessment.model] = (nrmse(predicted, m.force_N), rms_level_error(predicted, m.force_N))
            if name not in training_names:
                assessment.validation[name] = errors[name, assessment.model]
    return errors, predictions


@dataclass
class CouplingChoice:
    """How each model predicts the held-out multi-axis files with each coupling, and the coupling
    chosen for the recommended model: the lowest mean NRMSE of the force vector, where another is
    within ``PREDICTION_TOLERANCE`` of it the simpler (none before radial before spherical)."""
    errors: dict                        # (model, coupling): [NRMSE per file]
    files: list[str]
    couplings: tuple[str, ...]
    model: str
    chosen: str
    reason: str

    def format(self) -> str:
        lines = [f"held-out multi-axis files ({', '.join(self.files)}): mean NRMSE of the force vector"]
        lines.append(f"{'model':17s}" + "".join(f"{coupling:>12s}" for coupling in self.couplings))
        for model in dict.fromkeys(m for m, _ in self.errors):
            lines.append(f"{model:17s}" + "".join(f"{np.mean(self.errors[model, c]):12.2%}" for c in self.couplings))
        return "\n".join(lines)

    def write(self, path: Path) -> None:
        with writing(path) as temporary, open(temporary, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(["model", "coupling", "file", "vector_nrmse", "chosen"])
            for (model, coupling), values in self.errors.items():
                for name, value in zip(self.files, values):
                    writer.writerow([model, coupling, name, f"{value:.6g}",
                                     model == self.model and coupling == self.chosen])


def weigh_couplings(parameters: dict, bushings, multiaxis, couplings: Sequence[str], model: str,
                    tolerance: float = PREDICTION_TOLERANCE) -> CouplingChoice:
    """Each model's predictions of the multi-axis files with each coupling (``simulate.simulate_multiaxis``,
    ``multiaxis.COUPLED_AXES``: none, its one-axis model on each axis; radial, its coupled form on x and
    y, z alone; spherical, on x, y and z, which needs files of three axes), and the coupling for
    ``model`` (:class:`CouplingChoice`)."""
    from identification.forward.simulate import simulate_multiaxis
    from identification.measured.multiaxis import vector_nrmse
    errors = {}
    for bushing in bushings:
        for coupling in couplings:
            values = []
            for m in multiaxis:
                predicted = simulate_multiaxis(parameters[bushing.name], m.time_s, m.displacement_mm, bushing,
                                               coupling, m.velocity_mm_s)
                values.append(vector_nrmse(predicted, m.force_N))
            errors[bushing.name, coupling] = values
    means = {coupling: float(np.mean(errors[model, coupling])) for coupling in couplings}
    best = min(means.values())
    order = [c for c in ("none", "radial", "spherical") if c in couplings]
    chosen = next(c for c in order if means[c] <= (1.0 + tolerance) * best)
    others = ", ".join(f"{c} {means[c]:.2%}" for c in order if c != chosen)
    reason = (f"{model} predicts the held-out multi-axis files with {means[chosen]:.2%} NRMSE of the force vector"
              + (f" against {others}" if others else "")
              + ("; the simplest within 10 % of the best" if chosen != min(means, key=means.get) else ""))
    return CouplingChoice(errors, [m.name for m in multiaxis], tuple(couplings), model, chosen, reason)


def format_assessments(assessments: Sequence[Assessment], recommendation: Recommendation,
                       stopped: Sequence[Stopped] = ()) -> str:
    """One row per model: parameters, training against the noise, BIC, held-out errors; a model
    stopped after its screening, its screened misfit and why (``race``)."""
    best_bic = min(a.information_criterion for a in assessments)
    width = max([17] + [len(a.model) for a in assessments] + [len(s.model) for s in stopped])
    lines = [f"{'model':{width}s} {'params':>6s} {'worst NRMSE/floor':>17s} {'floor':>5s} {'chi2/n':>9s} {'dBIC':>9s} "
             f"{'held-out NRMSE':>14s} {'table err/unc':>13s}"]
    for a in assessments:
        held = f"{a.validation_error:.2%}" if a.validation_error is not None else "-"
        table = f"{a.table_error:.2f}" if a.table_error is not None else "-"
        mark = "  <- recommended" if a.model == recommendation.model else ""
        lines.append(f"{a.model:{width}s} {a.free_parameters:6d} {a.training_ratio:17.2f} "
                     f"{'yes' if a.at_floor else 'NO':>5s} {a.misfit:9.3f} {a.information_criterion - best_bic:9.1f} "
                     f"{held:>14s} {table:>13s}{mark}")
    for s in stopped:
        lines.append(f"{s.model:{width}s} {s.free_parameters:6d}  stopped {s.when}: {s.reason}")
    lines.append(f"floor: every training test's NRMSE within {FLOOR_FACTOR}x its noise level or, for a sine whose "
                 "device repeats less than that from cycle to cycle, its repeatability (a training table's "
                 f"rms error within {FLOOR_FACTOR}x its uncertainty; the column is the worst of them); dBIC: BIC = chi^2 + "
                 "d*ln(n) over the best; held-out NRMSE: the mean over the validation files that are not training "
                 f"files; table err/unc: rms error in units of {KDYN_UNCERTAINTY:.0%} on |K*| and "
                 f"{LOSS_ANGLE_UNCERTAINTY_DEG:g} deg")
    return "\n".join(lines)


def format_comparison(errors: dict, models: Sequence[str], files: Sequence[str], training: set[str] = frozenset()) -> str:
    """NRMSE per file (rows) and model (columns), the eq. 10 error in brackets."""
    width = max(len(name) for name in files) + 13
    column = max([22] + [len(model) + 1 for model in models])
    lines = [f"{'file':{width}s}" + "".join(f"{model:>{column}s}" for model in models)]
    for name in files:
        cells = "".join(f"{errors[name, model][0]:>{column - 10}.2%} ({errors[name, model][1]:+6.1%})"
                        for model in models)
        lines.append(f"{name + (' (training)' if name in training else ''):{width}s}{cells}")
    lines.append("NRMSE = rms(F_pre - F_exp)/rms(F_exp); (eq. 10) = (rms F_exp - rms F_pre)/rms F_exp")
    return "\n".join(lines)


def general_excitation_lines(validation, errors: dict, models: Sequence[str], repeats: float | None) -> list[str]:
    """For each validation file without steady cycles (``repeatability.estimate_repeatability``
    finds none: an earthquake, a random road), that its floor is its noise, and each model's
    NRMSE on it against what the device repeats on the training sines (``repeats``, a fraction;
    None: no training sine says)."""
    from identification.measured.repeatability import estimate_repeatability
    lines = []
    for m in validation:
        if estimate_repeatability(m.time_s, m.displacement_mm, m.force_N).known:
            continue
        name = Path(m.source).name
        if repeats is None:
            lines.append(f"{name} has no steady cycles: its floor is its noise, and no training sine says what the "
                         "device repeats")
            continue
        cells = ", ".join(f"{model} {errors[name, model][0] / repeats:.3g}x" for model in models)
        lines.append(f"{name} has no steady cycles (its floor is its noise); against what the device repeats on "
                     f"the training sines ({repeats:.2%}): {cells}")
    return lines


def format_table_errors(table: KdynTable, assessments: Sequence[Assessment]) -> str:
    """The largest and rms |K*| and loss-angle errors of each model on the held-out table."""
    lines = [f"held-out table {table.name} ({int(np.count_nonzero(table.weight > 0))} rows): "
             "|K*| error largest / rms, loss angle error largest / rms"]
    for a in assessments:
        kdyn, angle = np.abs(a.table.kdyn_errors), np.abs(a.table.angle_errors_deg)
        lines.append(f"  {a.model:17s} {np.max(kdyn):7.2%} / {np.sqrt(np.mean(kdyn ** 2)):6.2%}   "
                     f"{np.max(angle):6.2f} / {np.sqrt(np.mean(angle ** 2)):5.2f} deg")
    return "\n".join(lines)


def _write_csvs(out_dir: Path, assessments, recommendation: Recommendation, errors: dict, table,
                stopped: Sequence[Stopped] = ()) -> None:
    _write_comparison(out_dir, assessments, recommendation, stopped)
    with writing(out_dir / "validation.csv") as temporary, open(temporary, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["file", "model", "nrmse", "eq10_rms_level_error"])
        for (name, model), (error, eq10) in errors.items():
            writer.writerow([name, model, f"{error:.6g}", f"{eq10:.6g}"])
    if table is not None:
        kept = table.weight > 0
        with writing(out_dir / "kdyn_errors.csv") as temporary, open(temporary, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(["model", "amplitude_mm", "frequency_hz", "preload_mm", "kdyn_N_per_mm", "loss_angle_deg",
                             "kdyn_relative_error", "loss_angle_error_deg"])
            for a in assessments:
                for row, (X, f, P, kdyn, angle) in enumerate(zip(table.amplitude_mm[kept], table.frequency_hz[kept],
                                                                 table.preload_mm[kept], table.kdyn_N_per_mm[kept],
                                                                 table.loss_angle_deg[kept])):
                    writer.writerow([a.model, f"{X:g}", f"{f:g}", f"{P:g}", f"{kdyn:.6g}", f"{angle:.6g}",
                                     f"{a.table.kdyn_errors[row]:.6g}", f"{a.table.angle_errors_deg[row]:.6g}"])


def _write_comparison(out_dir: Path, assessments, recommendation: Recommendation | None,
                      stopped: Sequence[Stopped] = ()) -> None:
    """comparison.csv: a row per model (``recommended`` empty while the comparison runs,
    ``recommendation`` None)."""
    best_bic = min((a.information_criterion for a in assessments), default=math.nan)
    with writing(out_dir / "comparison.csv") as temporary, open(temporary, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["model", "free_parameters", "worst_nrmse_over_floor", "at_floor", "converged",
                         "misfit_chi2_per_residual", "residuals", "bic", "delta_bic", "held_out_mean_nrmse",
                         "table_error_over_uncertainty", "table_largest_kdyn_error", "table_largest_loss_angle_error_deg",
                         "seconds", "recommended", "screened_misfit_chi2_per_residual",
                         "first_stage_misfit_chi2_per_residual", "before_last_stage_misfit_chi2_per_residual",
                         "stopped_after_screening"])
        for a in assessments:
            kdyn = np.max(np.abs(a.table.kdyn_errors)) if a.table is not None else None
            angle = np.max(np.abs(a.table.angle_errors_deg)) if a.table is not None else None
            writer.writerow([a.model, a.free_parameters, _cell(a.training_ratio), a.at_floor, a.converged,
                             _cell(a.misfit), a.residuals, _cell(a.information_criterion),
                             _cell(a.information_criterion - best_bic), _cell(a.validation_error),
                             _cell(a.table_error), _cell(kdyn), _cell(angle), f"{a.seconds:.1f}",
                             "" if recommendation is None else a.model == recommendation.model,
                             _cell(a.screened_misfit),
                             _cell(a.first_stage_misfit), _cell(a.before_last_misfit), ""])
        for s in stopped:
            writer.writerow([s.model, s.free_parameters, "", False, False, "", "", "", "", "", "", "", "",
                             f"{s.seconds:.1f}", False, _cell(s.screened_misfit), _cell(s.first_stage_misfit),
                             _cell(s.before_last_misfit), s.reason])


def _cell(value) -> str:
    return "" if value is None else f"{value:.6g}"
