"""Verification report (paper §5): error tables and force plots for a parameter set.

Errors: the paper's eq. 10, (RMS(F_exp) - RMS(F_pre)) / RMS(F_exp), which cannot see a phase
or shape error, beside the stricter NRMSE, RMS(F_pre - F_exp) / RMS(F_exp).
The grid of §5: sine {1, 10, 20, 30} Hz x {0.5, 1, 2, 3} mm and step rise {0.1, 0.2, 0.4} s x
{1, 2, 3} mm held to 10 s (the paper's Table 7 repeats Table 6's numbers, a printing error),
plus a random input (peak 2 mm), all sampled at 1 kHz.
"""
from __future__ import annotations

import math

from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from fmu_src.model.registry import LINEAR_BASELINE
from identification.measured.measurements import Measurement
from identification.fitting.objectives import nrmse, rms_level_error
from identification.measured.signals import Random, Sine, Step, sample_times
from identification.fitting.search_space import KelvinVoigtFit
from identification.analysis.plots import plot_comparison
from identification.forward.parameter_sets import parameter_sets
from identification.analysis.predict import predict_sets
from identification.forward.simulate import simulate_set

SINE_FREQUENCIES_HZ = (1.0, 10.0, 20.0, 30.0)
SINE_AMPLITUDES_MM = (0.5, 1.0, 2.0, 3.0)
STEP_RISE_TIMES_S = (0.1, 0.2, 0.4)
STEP_AMPLITUDES_MM = (1.0, 2.0, 3.0)
RATE_HZ = 1000.0


@dataclass
class CaseError:
    case: str
    nrmse: float
    eq10: float
    band_mean_N: float | None = None   # an ensemble's band width (max - min), mean over the samples
    band_max_N: float | None = None


def grid_protocols():
    for frequency in SINE_FREQUENCIES_HZ:
        for amplitude in SINE_AMPLITUDES_MM:
            yield f"sine {amplitude:g} mm {frequency:g} Hz", Sine(amplitude, frequency, max(1.0, 2.0 / frequency))
    for rise in STEP_RISE_TIMES_S:
        for amplitude in STEP_AMPLITUDES_MM:
            yield f"step {amplitude:g} mm rise {rise:g} s", Step(amplitude, rise, 10.0)
    yield "random 2 mm", Random(2.0, 5.0, seed=7)


def _case(name: str, prediction, expected) -> CaseError:
    band = prediction.band_width_N if prediction.members > 1 else None
    return CaseError(name, nrmse(prediction.force_N, expected), rms_level_error(prediction.force_N, expected),
                     None if band is None else float(np.mean(band)), None if band is None else float(np.max(band)))


def grid_errors(parameters, truth, model: str | None = None, truth_model: str | None = None) -> list[CaseError]:
    """Errors of ``parameters`` (a set or an ensemble, anything ``predict`` takes; its best
    member) against the forces of ``truth`` (anything ``simulate`` takes: a mapping of
    ``truth_model``'s values, default the proposed model's, or a ``ParameterSet``; noise-free)
    over the §5 grid, with the ensemble's band width. Each is read and checked once."""
    bushing, sets = parameter_sets(parameters, model)
    truth_bushing, truth_sets = parameter_sets(truth, truth_model)
    errors = []
    for name, protocol in grid_protocols():
        t = sample_times(protocol.duration_s, RATE_HZ)
        signals = protocol.signals(t)
        expected = simulate_set(truth_bushing, truth_sets[0], t, *signals)
        errors.append(_case(name, predict_sets(bushing, sets, t, *signals), expected))
    return errors


def predict_record(bushing, sets, m: Measurement):
    """``predict_sets`` on a measured file as the fit takes it: from rest holding the force it
    holds before it moves, at its own temperature (a model with a temperature law)."""
    from identification.forward.population import conditioned_set
    from identification.measured.offsets import held_force
    sets = [bushing.check(conditioned_set(bushing, values, m.conditions)) for values in sets]
    return predict_sets(bushing, sets, m.time_s, m.displacement_mm, m.measured_velocity_mm_s,
                        held_force(m) if m.has_force else math.nan)


def data_errors(parameters, measurements: Sequence[Measurement], kelvin_voigt: KelvinVoigtFit | None = None,
                model: str | None = None) -> list[tuple[CaseError, CaseError | None]]:
    """Errors of ``parameters`` (a set or an ensemble, read and checked once) on measured files,
    each beside the Kelvin-Voigt fit's if one is given."""
    bushing, sets = parameter_sets(parameters, model)
    rows = []
    for m in measurements:
        prediction = predict_record(bushing, sets, m)
        name = Path(m.source).name
        baseline = None
        if kelvin_voigt is not None:
            linear = kelvin_voigt.force(m.displacement_mm, m.velocity_mm_s)
            baseline = CaseError(name, nrmse(linear, m.force_N), rms_level_error(linear, m.force_N))
        rows.append((_case(name, prediction, m.force_N), baseline))
    return rows


def _band(row: CaseError) -> str:
    return "" if row.band_mean_N is None else f" {row.band_mean_N:10.1f} {row.band_max_N:10.1f}"


def _band_header(rows) -> str:
    return f" {'band mean':>10s} {'band max':>10s}" if any(r.band_mean_N is not None for r in rows) else ""


def format_errors(rows: Sequence[CaseError]) -> str:
    lines = [f"{'case':45s} {'NRMSE':>8s} {'eq. 10':>8s}" + _band_header(rows)]
    lines += [f"{r.case:45s} {r.nrmse:8.2%} {r.eq10:8.2%}" + _band(r) for r in rows]
    if any(r.band_mean_N is not None for r in rows):
        lines.append("band: the ensemble's width max - min [N], mean and largest over the samples")
    return "\n".join(lines)


def format_data_errors(rows) -> str:
    with_baseline = any(baseline is not None for _, baseline in rows)
    header = (f"{'file':45s} {'NRMSE':>8s} {'eq. 10':>8s}" + _band_header([m for m, _ in rows])
              + (f" {'KV NRMSE':>9s} {'ratio':>6s}" if with_baseline else ""))
    lines = [header]
    for model, baseline in rows:
        line = f"{model.case:45s} {model.nrmse:8.2%} {model.eq10:8.2%}" + _band(model)
        if baseline is not None:
            line += f" {baseline.nrmse:9.2%} {model.nrmse / baseline.nrmse:6.2f}"
        lines.append(line)
    return "\n".join(lines)


def plot_measurement(parameters, measurement: Measurement, path: Path,
                     kelvin_voigt: KelvinVoigtFit | None = None, model: str | None = None) -> Path:
    """Force-time and force-displacement of measurement and model (and a Kelvin-Voigt fit),
    like the paper's Figs. 9-19; an ensemble's band shaded."""
    m = measurement
    bushing, sets = parameter_sets(parameters, model)
    prediction = predict_record(bushing, sets, m)
    predictions = {bushing: prediction.force_N}
    if kelvin_voigt is not None:
        predictions[LINEAR_BASELINE] = kelvin_voigt.force(m.displacement_mm, m.velocity_mm_s)
    band = (prediction.lower_N, prediction.upper_N) if prediction.members > 1 else None
    return plot_comparison(m, predictions, path, band)
