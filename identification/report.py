"""Verification report (paper §5): error tables and force plots for a parameter set.

Errors: the paper's eq. 10, (RMS(F_exp) - RMS(F_pre)) / RMS(F_exp), which cannot see a phase
or shape error, beside the stricter NRMSE, RMS(F_pre - F_exp) / RMS(F_exp).
The grid of §5: sine {1, 10, 20, 30} Hz x {0.5, 1, 2, 3} mm and step rise {0.1, 0.2, 0.4} s x
{1, 2, 3} mm held to 10 s (the paper's Table 7 repeats Table 6's numbers, a printing error),
plus a random input (peak 2 mm), all sampled at 1 kHz.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

from fmu_src.bushing_models import get_model
from identification.measurements import Measurement
from identification.objectives import nrmse, rms_error
from identification.protocols import Random, Sine, Step, sample_times
from identification.search_space import KelvinVoigtFit
from identification.plots import plot_comparison
from identification.simulate import simulate

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


def grid_protocols():
    for frequency in SINE_FREQUENCIES_HZ:
        for amplitude in SINE_AMPLITUDES_MM:
            yield f"sine {amplitude:g} mm {frequency:g} Hz", Sine(amplitude, frequency, max(1.0, 2.0 / frequency))
    for rise in STEP_RISE_TIMES_S:
        for amplitude in STEP_AMPLITUDES_MM:
            yield f"step {amplitude:g} mm rise {rise:g} s", Step(amplitude, rise, 10.0)
    yield "random 2 mm", Random(2.0, 5.0, seed=7)


def grid_errors(params: Mapping[str, float], truth: Mapping[str, float], model: str = "proposed",
                truth_model: str = "proposed") -> list[CaseError]:
    """Errors of ``params`` (of ``model``) against the forces of ``truth`` (of
    ``truth_model``, noise-free) over the §5 grid."""
    errors = []
    for name, protocol in grid_protocols():
        t = sample_times(protocol.duration_s, RATE_HZ)
        signals = protocol.signals(t)
        predicted = simulate(params, t, *signals, model=model)
        expected = simulate(truth, t, *signals, model=truth_model)
        errors.append(CaseError(name, nrmse(predicted, expected), rms_error(predicted, expected)))
    return errors


def data_errors(params: Mapping[str, float], measurements: Sequence[Measurement],
                kelvin_voigt: KelvinVoigtFit | None = None,
                model: str = "proposed") -> list[tuple[CaseError, CaseError | None]]:
    """Errors of ``params`` (of ``model``) on measured files, each beside the Kelvin-Voigt
    fit's if one is given."""
    rows = []
    for m in measurements:
        predicted = simulate(params, m.time_s, m.displacement_mm, m.measured_velocity_mm_s, model=model)
        name = Path(m.source).name
        fitted = CaseError(name, nrmse(predicted, m.force_N), rms_error(predicted, m.force_N))
        baseline = None
        if kelvin_voigt is not None:
            linear = kelvin_voigt.force(m.displacement_mm, m.velocity_mm_s)
            baseline = CaseError(name, nrmse(linear, m.force_N), rms_error(linear, m.force_N))
        rows.append((fitted, baseline))
    return rows


def format_errors(rows: Sequence[CaseError]) -> str:
    lines = [f"{'case':45s} {'NRMSE':>8s} {'eq. 10':>8s}"]
    lines += [f"{r.case:45s} {r.nrmse:8.2%} {r.eq10:8.2%}" for r in rows]
    return "\n".join(lines)


def format_data_errors(rows) -> str:
    with_baseline = any(baseline is not None for _, baseline in rows)
    header = f"{'file':45s} {'NRMSE':>8s} {'eq. 10':>8s}" + (f" {'KV NRMSE':>9s} {'ratio':>6s}" if with_baseline else "")
    lines = [header]
    for model, baseline in rows:
        line = f"{model.case:45s} {model.nrmse:8.2%} {model.eq10:8.2%}"
        if baseline is not None:
            line += f" {baseline.nrmse:9.2%} {model.nrmse / baseline.nrmse:6.2f}"
        lines.append(line)
    return "\n".join(lines)


def plot_measurement(params: Mapping[str, float], measurement: Measurement, path: Path,
                     kelvin_voigt: KelvinVoigtFit | None = None, model: str = "proposed") -> Path:
    """Force-time and force-displacement of measurement and model (and a Kelvin-Voigt fit),
    like the paper's Figs. 9-19."""
    m = measurement
    predictions = {model: simulate(params, m.time_s, m.displacement_mm, m.measured_velocity_mm_s, model=model)}
    if kelvin_voigt is not None:
        predictions["kelvin_voigt"] = kelvin_voigt.force(m.displacement_mm, m.velocity_mm_s)
    return plot_comparison(m, predictions, path)
