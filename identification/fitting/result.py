"""What a fit returns: the best set, each training test's fit, and the convergence evidence.

:class:`FitResult` is the front door's answer (``identification.fit``); :class:`RigTestFit` one
training test at the fitted parameters, :class:`TableFit` a dynamic-stiffness table's. A fit
is ``converged`` when every test is at its floor (NRMSE <= ``FLOOR_FACTOR`` x the larger of its
noise level and, for a sine, what the device repeats from cycle to cycle:
``identification.measured.repeatability``) and at least ``MIN_AGREEING`` starts of the last stage
reach the best misfit within the 95 % confidence threshold; otherwise ``warning`` says why, with
its figures.

Units: forces in N, NRMSE and noise levels as fractions of the rms force, misfit chi^2/n
(1 at the noise floor), loss angles in degrees.
"""
from __future__ import annotations

import math

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

import numpy as np

from fmu_src.model.derived import derive
from fmu_src.model.options.rig import RIG
from fmu_src.parameter_files import ParameterSet, save_ensemble, save_parameters
from identification.errors import FitNotConvergedWarning, IdentificationError  # noqa: F401  (also imported from here)
from identification.interrupt import deferred, writing
from identification.measured.kdyn_table import FIT_CYCLES, KDYN_UNCERTAINTY, LOSS_ANGLE_UNCERTAINTY_DEG
from identification.measured.noise import NoiseEstimate
from identification.measured.repeatability import Repeatability
from identification.forward.parameter_sets import FittedParameters
from identification.fitting.objectives import MIN_NOISE_FRACTION
from identification.fitting.presets import describe

if TYPE_CHECKING:
    from identification.fitting.ensemble import Identifiability, SamplerReport
    from identification.fitting.multistart import StartRecord
    from identification.fitting.search_space import SearchSpace

RIG_PARAMETERS = (("rig_displacement_zero", "offset", "mm"), ("rig_force_zero", "preload", "N"))
"""The rig's offsets (``fmu_src.model.derived``'s ``rig`` option), what an FMU's mounting calls
them where asked to take them, and their units."""

FLOOR_FACTOR = 1.25
"""A test is at its floor when the fit's NRMSE on it is at most this times its floor (the larger
of its noise level and its repeatability)."""
MIN_AGREEING = 2
"""Starts of the last stage that must reach the best misfit for a fit to be converged."""


@dataclass
class RigTestFit:
    """One training test at the fitted parameters: its noise level, for a sine what the device
    repeats from cycle to cycle (``repeatability``; None for other tests), the NRMSE, and the
    force it was computed from (``predicted_N`` [N] at the test's samples, (samples, axes) for a
    multi-axis test; kept so that nothing simulates it again)."""
    name: str
    kind: str
    noise: NoiseEstimate
    nrmse: float
    repeatability: Repeatability | None = None
    predicted_N: np.ndarray | None = field(default=None, repr=False, compare=False)

    @property
    def noise_fraction(self) -> float:
        """The noise level the fit works with: the estimate, at least MIN_NOISE_FRACTION of
        the rms force (what the objective divides by)."""
        return max(self.noise.relative, MIN_NOISE_FRACTION)

    @property
    def misfit_N(self) -> float:
        """The rms [N] of the fitted set's residual on the test (its NRMSE times its rms force):
        what the model demonstrably misses on its own training data."""
        return self.nrmse * self.noise.rms_force_N

    @property
    def repeat_fraction(self) -> float | None:
        """What the device does not repeat, as a fraction of the rms force (None: not a sine, or
        too few steady cycles)."""
        if self.repeatability is None or not self.repeatability.known:
            return None
        return self.repeatability.relative

    @property
    def floor_source(self) -> str:
        """What sets the floor: "repeatability" where the device repeats less than its noise
        says, else "noise"."""
        repeat = self.repeat_fraction
        return "repeatability" if repeat is not None and repeat > self.noise_fraction else "noise"

    @property
    def floor_fraction(self) -> float:
        """The NRMSE no model driven by the displacement can go below: the larger of the noise
        level and the repeatability."""
        return self.repeat_fraction if self.floor_source == "repeatability" else self.noise_fraction

    @property
    def floor_words(self) -> str:
        """What the floor is, for reports: "the noise" or "what the device repeats"."""
        return "what the device repeats" if self.floor_source == "repeatability" else "the noise"

    @property
    def noise_ratio(self) -> float:
        """The NRMSE over the noise level alone."""
        return self.nrmse / self.noise_fraction

    @property
    def ratio(self) -> float:
        """The NRMSE over the floor (:attr:`floor_fraction`)."""
        return self.nrmse / self.floor_fraction

    @property
    def at_floor(self) -> bool:
        return bool(self.ratio <= FLOOR_FACTOR)

    def as_dict(self) -> dict:
        out = {"file": self.name, "kind": self.kind, "noise_N": round_for_file(self.noise_fraction * self.noise.rms_force_N),
               "noise_fraction": round_for_file(self.noise_fraction), "nrmse": round_for_file(self.nrmse),
               "nrmse_over_noise": round_for_file(self.noise_ratio), "misfit_N": round_for_file(self.misfit_N)}
        if self.predicted_N is not None:
            out["samples"] = int(np.shape(self.predicted_N)[0])
        if self.repeat_fraction is not None:
            out["repeatability_fraction"] = round_for_file(self.repeat_fraction)
        out.update({"floor": self.floor_source, "nrmse_over_floor": round_for_file(self.ratio), "at_floor": self.at_floor})
        return out


def sines_repeatability(tests: Sequence[RigTestFit]) -> float | None:
    """The mean of what the device repeats on the sines of ``tests`` whose repeatability is known
    (a fraction of each one's rms force), or None without any."""
    known = [t.repeat_fraction for t in tests if t.repeat_fraction is not None]
    return float(np.mean(known)) if known else None


def general_excitation_notes(tests: Sequence[RigTestFit]) -> list[str]:
    """For each test without steady cycles (a random input, an earthquake), that its floor is its
    noise alone, and its NRMSE against what the device repeats on the sines among ``tests``: the
    floor a model driven by the displacement can reach on the device."""
    repeats = sines_repeatability(tests)
    notes = []
    for t in tests:
        if t.kind == "random" and t.repeat_fraction is None:
            beside = (f"; {t.nrmse / repeats:.3g}x what the device repeats on its sines ({repeats:.2%})"
                      if repeats is not None else "")
            notes.append(f"note: {t.name} has no steady cycles to repeat: its floor is its noise ({t.noise_fraction:.2%})"
                         + beside)
    return notes


@dataclass
class TableFit:
    """A dynamic-stiffness table at the fitted parameters: the converged characterisation
    (``dynamic_stiffness.characterise``) against the table's rows of weight > 0."""
    name: str
    kdyn_errors: np.ndarray          # relative |K*| error per row
    angle_errors_deg: np.ndarray     # loss-angle error per row [deg]
    weight: np.ndarray
    cycles_error: float              # largest |K*| difference of the fit's fixed-cycle loop from its steady state

    @property
    def ratio(self) -> float:
        """The rms of the weighted errors in uncertainty units (KDYN_UNCERTAINTY,
        LOSS_ANGLE_UNCERTAINTY_DEG): 1 where the fit matches the table to its uncertainty."""
        scaled = np.concatenate([self.kdyn_errors / KDYN_UNCERTAINTY, self.angle_errors_deg / LOSS_ANGLE_UNCERTAINTY_DEG])
        return float(np.sqrt(np.mean((np.tile(self.weight, 2) * scaled) ** 2)))

    @property
    def at_floor(self) -> bool:
        return bool(self.ratio <= FLOOR_FACTOR)

    def as_dict(self) -> dict:
        return {"file": self.name, "kind": "kdyn", "rows": int(self.weight.size),
                "rms_kdyn_error": round_for_file(float(np.sqrt(np.mean(self.kdyn_errors ** 2)))),
                "largest_kdyn_error": round_for_file(float(np.max(np.abs(self.kdyn_errors)))),
                "rms_loss_angle_error_deg": round_for_file(float(np.sqrt(np.mean(self.angle_errors_deg ** 2)))),
                "largest_loss_angle_error_deg": round_for_file(float(np.max(np.abs(self.angle_errors_deg)))),
                "uncertainty": {"kdyn": KDYN_UNCERTAINTY, "loss_angle_deg": LOSS_ANGLE_UNCERTAINTY_DEG},
                "fit_loop_kdyn_difference": round_for_file(self.cycles_error),
                "error_over_uncertainty": round_for_file(self.ratio), "at_floor": self.at_floor}

    def format(self) -> str:
        d = self.as_dict()
        return (f"{self.name:44s} {'kdyn':7s} |K*| rms {d['rms_kdyn_error']:.2%} (largest {d['largest_kdyn_error']:.2%}), "
                f"loss angle rms {d['rms_loss_angle_error_deg']:.2f} deg (largest {d['largest_loss_angle_error_deg']:.2f}); "
                f"{self.ratio:.2f}x the uncertainty ({KDYN_UNCERTAINTY:.0%}, {LOSS_ANGLE_UNCERTAINTY_DEG:g} deg)  "
                f"{'yes' if self.at_floor else 'NO'}")


def information_criterion(misfit: float, free_parameters: int, residuals: int) -> float:
    """Schwarz's BIC with the noise levels known: chi^2 + d*ln(n), chi^2 = n*misfit over n
    residuals, d the free parameters; lower is better, and a model must lower chi^2 by ln(n) per
    parameter it adds."""
    return residuals * misfit + free_parameters * math.log(max(residuals, 1))


@dataclass
class FitResult(FittedParameters):
    """What ``fit`` returns: the best parameter set, the evidence that it is the optimum, and
    how sure it is.

    Attributes
    ----------
    parameters : ParameterSet
        The best fit (paper's N-mm-s units) with its provenance.
    misfit : float
        chi^2/n over every sample, 1 at the noise floor.
    tests : list of RigTestFit
        Each training test's NRMSE against its noise level.
    records : list of StartRecord
        Every start, the last stage's first, by misfit.
    threshold : float
        Misfit increase within the 95 % confidence region.
    ensemble : list of dict
        Parameter sets within the region, the best first (``predict`` gives their band).
    converged : bool
        Every test at its floor and at least ``MIN_AGREEING`` final starts agree; ``warning``
        says why not.
    """
    parameters: ParameterSet               # the best fit, with its provenance
    misfit: float                          # chi^2/n, 1 at the noise floor
    tests: list[RigTestFit]
    records: list[StartRecord]             # every start, the last stage's first, by misfit
    threshold: float                       # misfit increase within the 95 % confidence region
    ensemble: list[dict[str, float]]       # the best first
    identifiability: Identifiability | None
    preset: str
    seed: int
    evaluations: int
    seconds: float
    engine: str = "1 process"
    space: SearchSpace | None = None
    final_starts: int = 1
    sampler: SamplerReport | None = None
    notes: list[str] = field(default_factory=list)
    steps_per_sample: list[int] = field(default_factory=list)   # the forward model's, per test
    table: TableFit | None = None          # the dynamic-stiffness table, if one was fitted
    added_starts: int = 0                  # starts that ran the last stage because one alone reached the best
    agreed_before_added: int | None = None  # the agreement count when the last stage ended, before any added start
    ensemble_sampled: bool = True          # False: fit(ensemble=False), the ensemble is the best fit alone
    residuals: int = 0                     # n, the residuals chi^2/n is over (0: not recorded)
    failed_starts: int = 0                 # starts and profiles whose residuals or Jacobian were not finite
    coupling: str | None = None            # how the model ran on the multi-axis tests (None: there were none)
    screened_misfit: float | None = None   # the global phase's best chi^2/n (None: no search, a linear model)
    first_stage_misfit: float | None = None  # the best chi^2/n after the first least-squares stage
    before_last_misfit: float | None = None  # the best chi^2/n after every stage but the last
    method: str | None = None              # the search as it ran, in words (None: the preset's)

    @property
    def free_parameters(self) -> int:
        """The parameters the fit chose: its search box's coordinates (Kelvin-Voigt: k and c)."""
        return len(self.space.names) if self.space is not None else 2

    @property
    def information_criterion(self) -> float:
        """Schwarz's BIC of the fit (:func:`information_criterion`)."""
        return information_criterion(self.misfit, self.free_parameters, self.residuals)

    @property
    def model(self) -> str:
        return self.parameters.model.name

    @property
    def agreeing(self) -> int:
        """Starts of the last stage whose misfit is within the threshold of the best."""
        return agreeing_starts(self.records, self.records[0].stage, self.misfit, self.threshold) if self.records else 1

    @property
    def at_floor(self) -> bool:
        return all(t.at_floor for t in self.tests) and (self.table is None or self.table.at_floor)

    @property
    def floor_misfit(self) -> float:
        """The largest chi^2/n (which is in noise units) a fit at the floor of every test can
        have, but for FLOOR_FACTOR: 1 where the noise sets every floor, (repeatability/noise)^2 of
        the test with the most where the device repeats less than its noise says (the race's
        bound, ``identification.analysis.race``)."""
        return max([(t.floor_fraction / t.noise_fraction) ** 2 for t in self.tests], default=1.0)

    @property
    def converged(self) -> bool:
        enough = self.agreeing >= MIN_AGREEING or self.space is None   # Kelvin-Voigt: exact optimum
        return self.at_floor and enough

    @property
    def warning(self) -> str | None:
        """The ``not converged`` message with its figures, or None."""
        if self.converged:
            return None
        reasons = []
        worst = max(self.tests, key=lambda t: t.ratio) if self.tests else None
        failed = [t.name for t in self.tests if not math.isfinite(t.nrmse)]
        if failed:
            reasons.append(f"the fitted set's simulation fails on {', '.join(failed)} (too many substeps or an "
                           "overflow on its whole record, where the fit ran every stride-th sample or a prefix)")
        elif worst is not None and not worst.at_floor:
            reasons.append(f"training NRMSE {worst.nrmse:.2%} on {worst.name} is {worst.ratio:.2f}x "
                           f"{worst.floor_words} ({worst.floor_fraction:.2%}; the floor is {FLOOR_FACTOR}x)")
        if self.table is not None and not self.table.at_floor:
            reasons.append(f"the table {self.table.name} is matched to {self.table.ratio:.2f}x its uncertainty "
                           f"({KDYN_UNCERTAINTY:.0%} on |K*|, {LOSS_ANGLE_UNCERTAINTY_DEG:g} deg; the floor is "
                           f"{FLOOR_FACTOR}x)")
        if self.space is not None and self.agreeing < MIN_AGREEING:
            reasons.append(f"only {self.agreeing} of {self.final_starts} final starts reach the best misfit")
        edges = self.at_box_edge()
        if edges:
            hint = (f"the best fit lies on the search box's bound in {', '.join(edges)}: the parameters that "
                    "describe these data may lie outside the box (see identification/fitting/search_space.py)")
        elif self.space is not None and self.agreeing < MIN_AGREEING:
            hint = "more starts (--starts, --screening) may find a better optimum"
        elif worst is not None and worst.floor_source == "repeatability":
            hint = ("the starts agree, so the model does not describe what the device repeats from cycle to cycle: "
                    "a model with more of the device's physics may (bushing-identify compare)")
        else:
            hint = ("the starts agree, so the model may not describe these data to their noise level "
                    "(or the noise estimate is low: correlated noise reads low; a sine's repeatability tells)")
        return f"not converged: {'; '.join(reasons)}; {hint}"

    def at_box_edge(self, tolerance: float = 1e-3) -> list[str]:
        """The searched coordinates of the best fit within ``tolerance`` of the box's size from
        an upper bound, or from a lower bound that is a limit of the search (the time constants'
        floor, n >= 0.1). Other lower bounds stand for a physical limit a fit may rightly sit on:
        no spring or dashpot (1e-3 k_ref, 1e-4 c_ref), A >= 1, beta >= 0 and the shape sums >= 0."""
        if self.space is None:
            return []
        theta = self.space.to_coordinates(self.parameters.parameters)
        edges = []
        for c, value, (low, high) in zip(self.space.coordinates, theta, self.space.bounds()):
            margin = tolerance * (high - low)
            if value >= high - margin or (value <= low + margin and c.kind.floor_is_search_limit):
                edges.append(c.parameter)
        return edges

    def provenance(self) -> dict:
        """What the parameter file records of the fit: everything but timings and engine, so
        that the same seed gives the same file on any engine."""
        out = {"method": self._method(), "preset": self.preset, "seed": self.seed,
               "converged": self.converged, "misfit_chi2_per_residual": round_for_file(self.misfit),
               "tests": [t.as_dict() for t in self.tests] + ([self.table.as_dict()] if self.table else [])}
        if self.coupling is not None:
            out["multiaxis_coupling"] = self.coupling
        if self.rig_offsets:
            out["rig_offsets"] = {name: {"value": round_for_file(value), "uncertainty_95": round_for_file(spread),
                                         "unit": unit} for name, (value, spread, unit) in self.rig_offsets.items()}
        if self.space is not None:
            out.update({"starts_agreeing": self.agreeing, "final_starts": self.final_starts,
                        "starts_added_for_agreement": self.added_starts,
                        "starts_agreeing_before_added": self.agreed_before_added,
                        "failed_starts": self.failed_starts,
                        "agreement_threshold_misfit": round_for_file(self.threshold),
                        "ensemble_members": len(self.ensemble), "ensemble_sampled": self.ensemble_sampled,
                        "steps_per_sample": list(self.steps_per_sample),
                        "search_space": {"k_ref_N_per_mm": round_for_file(self.space.k_ref),
                                         "c_ref_Ns_per_mm": round_for_file(self.space.c_ref),
                                         "F_ref_N": round_for_file(self.space.F_ref),
                                         "x_ref_mm": round_for_file(self.space.x_ref),
                                         "shortest_time_constant_s": round_for_file(self.space.shortest_time_constant_s)}})
            if self.space.bushing.search.unit_weights:
                out["note"] = ("alpha = 1 in every Bouc-Wen block: the (alpha, A, beta, gamma) redundancy "
                               "(search_space.rescale_hysteresis gives the equivalent sets)")
        if self.sampler is not None:
            out["posterior_sampling"] = {"acceptance": round_for_file(self.sampler.acceptance),
                                         "autocorrelation_steps": round_for_file(self.sampler.autocorrelation_steps),
                                         "kept_steps": self.sampler.kept_steps}
        if self.identifiability is not None:
            out["weak_directions"] = [{k: (round_for_file(v) if not isinstance(v, dict) else {n: round_for_file(x) for n, x in v.items()})
                                       for k, v in entry.items()} for entry in self.identifiability.weakest()]
        return out

    def _method(self) -> str:
        if self.space is None:
            return "linear least squares F = k*x + c*v on the tests other than steps"
        return self.method or describe(self.preset)

    def summary(self) -> str:
        """A report like lmfit's fit_report: figures first, then the warnings."""
        fitted = f"{len(self.tests)} test(s)" + (f" and the table {self.table.name}" if self.table else "")
        lines = [f"{self.parameters.model.title} fitted to {fitted}, preset {self.preset!r}, "
                 f"seed {self.seed}, {self.evaluations} simulations in {self.seconds:.1f} s on {self.engine}",
                 f"misfit chi^2/n = {self.misfit:.4f} (1 = the noise floor)"]
        lines.append(f"{'test':44s} {'kind':7s} {'noise':>8s} {'repeats':>8s} {'NRMSE':>8s}  over the floor")
        for t in self.tests:
            repeats = f"{t.repeat_fraction:8.2%}" if t.repeat_fraction is not None else f"{'-':>8s}"
            lines.append(f"{t.name:44s} {t.kind:7s} {t.noise_fraction:8.2%} {repeats} {t.nrmse:8.2%}  "
                         f"{t.ratio:.2f}x {t.floor_words}: {'at the floor' if t.at_floor else 'NOT at the floor'}")
        unknown = [t for t in self.tests if t.kind == "sine" and t.repeat_fraction is None and t.repeatability]
        for t in unknown:
            lines.append(f"note: {t.name}: {t.repeatability.describe()}; its floor is the noise level alone")
        lines += general_excitation_notes(self.tests)
        if self.table is not None:
            lines.append(self.table.format())
            if self.table.cycles_error > 0.1 * KDYN_UNCERTAINTY:
                lines.append(f"note: the fit's fixed-cycle loop ({FIT_CYCLES} cycles a row or the model's settling "
                             f"time) differs from the steady state by up to "
                             f"{self.table.cycles_error:.2%} in |K*| at the fitted set (a slow transient); more than "
                             "a tenth of the table's uncertainty")
        if self.space is not None:
            lines.append(f"starts: {self.agreeing} of {self.final_starts} final starts agree (misfit within "
                         f"{self.threshold:.2e} of the best: delta chi^2 at 95 % for {len(self.space.names)} parameters); "
                         + (f"ensemble: {len(self.ensemble)} parameter sets" if self.ensemble_sampled
                            else "ensemble: not sampled (ensemble=False, --no-ensemble), the best fit alone"))
            if self.failed_starts:
                lines.append(f"failed starts: {self.failed_starts} (their residuals or Jacobian were not finite: "
                             "skipped, each kept at its last finite point)")
        if self.rig_offsets:
            lines.append("rig offsets (nuisance parameters, kept out of the parameter file's model unless asked): "
                         + ", ".join(f"{name.replace('rig_', '').replace('_', ' ')} {value:.4g} {unit}"
                                     + (f" +- {spread:.2g}" if math.isfinite(spread) else " (no ensemble: no band)")
                                     for name, (value, spread, unit) in self.rig_offsets.items()))
        if self.coupling is not None:
            lines.append(f"multi-axis tests: the model runs with the {self.coupling} coupling on them "
                         "(NRMSE of the force vector; noise: the rms of its axes')")
        if self.steps_per_sample:
            lines.append("forward model: " + ", ".join(f"{m} step{'s' if m > 1 else ''} per sample on {t.name}"
                                                       for m, t in zip(self.steps_per_sample, self.tests)))
        if self.identifiability is not None:
            lines.append(self.identifiability.format())
        if self.sampler is not None:
            lines.append(self.sampler.format())
        lines += self.notes
        lines.append("converged: yes" if self.converged else f"converged: no ({self.warning})")
        return "\n".join(lines)

    @property
    def rig_offsets(self) -> dict[str, tuple[float, float, str]]:
        """{rig parameter: (the fit's value, the ensemble's largest distance from it: the 95 %
        region's half width, or nan where the ensemble was not sampled, unit)} of a model with the
        ``rig`` option, but those the fit held; empty otherwise."""
        options = self.parameters.model.options
        if options is None or RIG not in options:
            return {}
        held = {name for name, _ in self.space.fixed} if self.space is not None else set()
        out = {}
        for name, _, unit in RIG_PARAMETERS:
            if name in held:        # held (fixed=...): not a result of the fit
                continue
            value = float(self.parameters.parameters[name])
            members = [float(member[name]) for member in self.ensemble[1:]]
            spread = max((abs(m - value) for m in members), default=math.nan) if self.ensemble_sampled else math.nan
            out[name] = (value, spread, unit)
        return out

    def for_fmu(self, members, into_fmu: bool = False) -> tuple[object, list[dict[str, float]]]:
        """(the model an FMU gets, ``members`` as its parameter sets): a model fitted with the rig's
        offsets without them (they are the test rig's, not the bushing's), or with them as its
        mounting's ``offset`` and ``preload`` where ``into_fmu``; any other model as it is."""
        model = self.parameters.model
        if model.options is None or RIG not in model.options:
            return model, [dict(member) for member in members]
        bushing = derive(model.base, model.options.without(RIG))
        mounting = {spec.name for spec in bushing.mounting_specs}
        sets = []
        for member in members:
            out = {name: value for name, value in member.items() if not name.startswith("rig_")}
            if into_fmu:
                for name, port, _ in RIG_PARAMETERS:
                    if port in mounting:
                        out[port] = member[name]
                    else:      # the model's own parameter of that name (Kelvin-Voigt's preload): the same force
                        out[port] = out[port] + member[name]
            sets.append(out)
        return bushing, sets

    def save(self, path: str | Path, ssv: str | Path | None = None, ensemble: str | Path | None = None,
             data: Sequence[str] = (), rig_into_fmu: bool = False) -> list[Path]:
        """Write the fit's files: what ``build_fmu.py --params`` and ``predict`` read.

        Parameters
        ----------
        path : str or Path
            The parameter file: JSON with the best set (paper's N-mm-s units) and the fit's
            provenance (method, seed, convergence evidence, each test's noise and NRMSE).
        ssv : str or Path, optional
            Also an SSP 1.0 ParameterValues file of the best set (values and units only).
        ensemble : str or Path, optional
            Also the ensemble (JSON, the best set first); refused for a fit run with
            ``ensemble=False``.
        data : sequence of str
            The training files, recorded in the provenance.
        rig_into_fmu : bool
            A model fitted with the rig's offsets (``+rig``): write them as its mounting's ``offset``
            and ``preload`` (default: only in the provenance, ``rig_offsets``, the model without them).

        Returns
        -------
        list of Path
            The files written. Each is written beside its place and renamed into it: an
            existing file is replaced whole or left as it was.

        Raises
        ------
        IdentificationError
            ``ensemble`` given for a fit without an ensemble (nothing is written).
        OSError
            A file that cannot be written.
        """
        if ensemble is not None and not self.ensemble_sampled:
            raise IdentificationError(f"no ensemble to write to {ensemble}: this fit ran with ensemble=False "
                                      "(--no-ensemble); fit again without it for the ensemble")
        provenance = dict(self.provenance(), data=[str(d) for d in data])
        if self.parameters.model.options is not None and RIG in self.parameters.model.options:
            provenance["rig_offsets_in_fmu"] = bool(rig_into_fmu)
        model, (best, *_) = self.for_fmu([self.parameters.parameters], rig_into_fmu)
        # each file whole or not at all, and a Ctrl-C or SIGTERM held until the set is written
        with deferred():
            with writing(path) as temporary:
                save_parameters(temporary, best, model.name, provenance)
            if ssv is not None:
                with writing(ssv) as temporary:
                    save_parameters(temporary, best, model.name)
            if ensemble is not None:
                with writing(ensemble) as temporary:
                    save_ensemble(temporary, self.for_fmu(self.ensemble, rig_into_fmu)[1], model.name, provenance)
        return [Path(file) for file in (path, ssv, ensemble) if file is not None]


def agreeing_starts(records: list[StartRecord], stage: int, best_misfit: float, threshold: float) -> int:
    """Starts that ran ``stage`` and reached ``best_misfit`` within ``threshold`` (a failed start
    never agrees): the agreement count, the convergence evidence."""
    return int(sum(r.misfit <= best_misfit + threshold for r in records if r.stage == stage and not r.failed))


def round_for_file(value):
    """Floats as the parameter file stores them (12 significant digits: stable text)."""
    return float(f"{value:.12g}") if isinstance(value, float) else value
