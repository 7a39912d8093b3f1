"""Which test to run next: the candidate on which the ensemble disagrees most.

The ensemble of a fit (``fit --ensemble``) holds the parameter sets the training tests cannot
tell apart. A test on which they predict different forces would tell them apart; a test on
which they agree would not. Every candidate test is simulated with every member (one
compiled population call each), and ranked by its *spread*: the rms over the test's samples
of the members' standard deviation [N]. The candidates: sines over amplitude x frequency and
steps over amplitude x rise time (held 10 s, as the paper's), the paper's §5 ranges and a
little beyond (CANDIDATE_* below); a candidate on which the best member, or all members but
one, cannot be simulated (overflow) is not proposed.

When the spread of every candidate is below the noise level of the training tests, a further
test would not separate the members from the noise: none is recommended, so that
design -> test -> refit can loop until this says so.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fmu_src.parameter_files import read_ensemble
from identification.forward.population import parameter_matrix
from identification.errors import IdentificationError
from identification.fitting.progress import bar as progress_bar
from identification.forward.input_path import prepare_input
from identification.forward.parameter_sets import parameter_sets
from identification.measured.signals import Sine, Step, sample_times
from identification.forward.simulate import simulate_driven

CANDIDATE_SINE_AMPLITUDES_MM = (0.5, 1.0, 2.0, 3.0, 4.0)
CANDIDATE_SINE_FREQUENCIES_HZ = (1.0, 5.0, 10.0, 20.0, 30.0, 40.0)
CANDIDATE_STEP_AMPLITUDES_MM = (1.0, 2.0, 3.0, 4.0)
CANDIDATE_RISE_TIMES_S = (0.05, 0.1, 0.2, 0.4)
STEP_HOLD_S = 10.0
RATE_HZ = 1000.0


@dataclass(frozen=True)
class Candidate:
    kind: str                          # "sine" or "step"
    amplitude_mm: float
    frequency_hz: float | None = None  # sine
    rise_time_s: float | None = None   # step

    @property
    def protocol(self):
        if self.kind == "sine":
            return Sine(self.amplitude_mm, self.frequency_hz, max(1.0, 2.0 / self.frequency_hz))
        return Step(self.amplitude_mm, self.rise_time_s, STEP_HOLD_S)

    def describe(self) -> str:
        if self.kind == "sine":
            return f"sine {self.amplitude_mm:g} mm at {self.frequency_hz:g} Hz"
        return f"step {self.amplitude_mm:g} mm, rise {self.rise_time_s:g} s, held to {STEP_HOLD_S:g} s"

    def as_dict(self) -> dict:
        out = {"kind": self.kind, "amplitude_mm": self.amplitude_mm}
        out.update({"frequency_hz": self.frequency_hz} if self.kind == "sine" else {"rise_time_s": self.rise_time_s})
        return out


def candidate_tests() -> list[Candidate]:
    return ([Candidate("sine", a, frequency_hz=f) for a in CANDIDATE_SINE_AMPLITUDES_MM
             for f in CANDIDATE_SINE_FREQUENCIES_HZ]
            + [Candidate("step", a, rise_time_s=r) for a in CANDIDATE_STEP_AMPLITUDES_MM
               for r in CANDIDATE_RISE_TIMES_S])


@dataclass(frozen=True)
class Ranked:
    candidate: Candidate
    spread_N: float                    # rms over the samples of the members' standard deviation
    rms_force_N: float                 # rms of the best member's force on the test


@dataclass
class Design:
    ranked: list[Ranked]               # every candidate, largest spread first
    noise_N: float                     # the training tests' (largest) noise level
    members: int

    def recommended(self, count: int = 3) -> list[Ranked]:
        """The top ``count`` candidates whose spread exceeds the noise level (none when no
        candidate's does: no further test is needed)."""
        return [r for r in self.ranked if r.spread_N > self.noise_N][:count]

    def as_json(self, count: int = 3) -> dict:
        return {"recommended": [{**r.candidate.as_dict(), "spread": r.spread_N} for r in self.recommended(count)],
                "largest_spread_N": self.ranked[0].spread_N if self.ranked else 0.0,
                "noise_N": self.noise_N, "members": self.members}

    def format(self, count: int = 3) -> str:
        lines = [f"{self.members} ensemble members; noise level of the training tests {self.noise_N:.1f} N"]
        chosen = self.recommended(count)
        if not chosen:
            lines.append(f"no further test needed: the largest spread, {self.ranked[0].spread_N:.1f} N "
                         f"({self.ranked[0].candidate.describe()}), is below the noise level")
            return "\n".join(lines)
        lines.append(f"{'rank':4s} {'next test':44s} {'spread [N]':>11s} {'x noise':>8s} {'rms force [N]':>14s}")
        for i, r in enumerate(chosen, start=1):
            lines.append(f"{i:4d} {r.candidate.describe():44s} {r.spread_N:11.1f} {r.spread_N / self.noise_N:8.1f} "
                         f"{r.rms_force_N:14.0f}")
        return "\n".join(lines)


def design(ensemble, noise_N: float | None = None, candidates: list[Candidate] | None = None,
           progress: bool = False) -> Design:
    """Rank ``candidates`` (default: :func:`candidate_tests`) by the spread of ``ensemble``
    (anything ``predict`` takes with several members). ``noise_N``: the noise level to compare
    with (default: the largest of the training tests' in the ensemble's provenance)."""
    if isinstance(ensemble, (str, Path)):     # read once: its sets and its fit's record of the noise
        ensemble = read_ensemble(ensemble)
    bushing, sets = parameter_sets(ensemble)
    if len(sets) < 2:
        raise IdentificationError("the design needs an ensemble of at least 2 parameter sets (fit --ensemble FILE)")
    if noise_N is None:
        noise_N = _training_noise(ensemble)
    candidates = candidates or candidate_tests()
    matrix = parameter_matrix(sets, bushing)
    ranked = []
    bar = progress_bar(len(candidates), "candidate tests", "test", progress)
    for candidate in candidates:
        if bar is not None:
            bar.update(1)
        protocol = candidate.protocol
        t = sample_times(protocol.duration_s, RATE_HZ)
        x, v = protocol.signals(t)
        driven = prepare_input(t, x, v, decimate_holds=True)
        forces = simulate_driven(matrix, driven, model=bushing)
        runs = np.all(np.isfinite(forces), axis=1)
        if runs.sum() < 2 or not runs[0]:
            continue   # the best set, or all but one, cannot be simulated on it: not a test to propose
        # each kept sample of a decimated hold stands for the samples up to the next kept one
        weights = np.diff(np.append(driven.sample_index, t.size))
        spread = float(np.sqrt(np.average(np.var(forces[runs], axis=0), weights=weights)))
        rms = float(np.sqrt(np.average(forces[0] ** 2, weights=weights)))
        ranked.append(Ranked(candidate, spread, rms))
    if bar is not None:
        bar.close()
    if not ranked:
        raise IdentificationError("the ensemble's best member cannot be simulated on any candidate test")
    ranked.sort(key=lambda r: -r.spread_N)
    return Design(ranked, float(noise_N), len(sets))


def _training_noise(ensemble) -> float:
    provenance = getattr(ensemble, "provenance", None)
    if not isinstance(provenance, dict) and hasattr(ensemble, "parameters"):   # a FitResult
        provenance = ensemble.parameters.provenance
    levels = [t.get("noise_N") for t in (provenance or {}).get("tests", []) if t.get("noise_N")]
    if not levels:
        raise IdentificationError("the ensemble's file records no noise level of its training tests; give the "
                                  "noise level in N (--noise)")
    return float(max(levels))

