"""Local sensitivity of the force to each of the 16 parameters (paper §4.1.1, §4.2.1).

One parameter at a time is changed by +-delta (relative, default 10 %) while the others keep
their values, as the paper does in ADAMS. The sensitivity is the relative force change per
relative parameter change (a central difference):

- sine: RMS(F(p+) - F(p-)) / (2*delta*RMS(F(p)))   (the paper's 2 mm, 10 Hz sine)
- step: |F(p+) - F(p-)| / (2*delta*|F(p)|) at the rise time and at the end of the hold
  (the paper's 2 mm step, 0.4 s rise, held to 10 s)

and the parameters are ranked by it (1 = most significant), beside the paper's ranks.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from fmu_src.models.proposed_model import PARAMETER_NAMES, PARAMETER_UNITS
from identification.errors import IdentificationError
from identification.forward.input_path import prepare_input
from identification.measured.signals import Sine, Step, sample_times
from identification.forward.simulate import simulate_driven

# "Significance priority" as printed in the paper: Table 1 (sine), Table 3 (step, t = T_r and 10 s).
PAPER_RANKS = {
    "sine": dict(c0=11, k0=3, beta1=13, gamma1=15, n1=10, alpha1=8, c1=14, k1=5,
                 c2=12, k2=16, beta2=6, gamma2=2, n2=1, alpha2=4, A1=9, A2=7),
    "step_rise": dict(c0=7, k0=1, beta1=10, gamma1=11, n1=13, alpha1=2, c1=16, k1=5,
                      c2=14, k2=15, beta2=12, gamma2=6, n2=4, alpha2=8, A1=3, A2=9),
    "step_end": dict(c0=10, k0=1, beta1=6, gamma1=7, n1=3, alpha1=4, c1=8, k1=5,
                     c2=9, k2=11, beta2=12, gamma2=13, n2=15, alpha2=14, A1=2, A2=16),
}
MEASURES = ("sine", "step_rise", "step_end")


@dataclass
class SensitivityTable:
    values: dict[str, dict[str, float]]  # measure -> parameter -> sensitivity
    delta: float

    def ranks(self, measure: str) -> dict[str, int]:
        order = sorted(PARAMETER_NAMES, key=lambda name: -self.values[measure][name])
        return {name: order.index(name) + 1 for name in PARAMETER_NAMES}

    def rows(self) -> list[dict]:
        ranks = {measure: self.ranks(measure) for measure in MEASURES}
        return [{"parameter": name, "unit": PARAMETER_UNITS[name],
                 **{f"{m}_sensitivity": self.values[m][name] for m in MEASURES},
                 **{f"{m}_rank": ranks[m][name] for m in MEASURES},
                 **{f"{m}_paper_rank": PAPER_RANKS[m][name] for m in MEASURES}} for name in PARAMETER_NAMES]

    def format(self) -> str:
        lines = [f"Local sensitivity, +-{self.delta:.0%} one at a time (rank; paper's rank in brackets)",
                 f"{'parameter':10s} {'sine 2 mm 10 Hz':>22s} {'step at rise time':>22s} {'step at end':>22s}"]
        for row in sorted(self.rows(), key=lambda r: r["sine_rank"]):
            cells = [f"{row[f'{m}_sensitivity']:9.3g} {row[f'{m}_rank']:3d} [{row[f'{m}_paper_rank']:2d}]"
                     for m in MEASURES]
            lines.append(f"{row['parameter']:10s} " + " ".join(f"{c:>22s}" for c in cells))
        return "\n".join(lines)

    def write_csv(self, path) -> None:
        rows = self.rows()
        with open(path, "w", newline="") as stream:
            writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)


def sensitivity(params: Mapping[str, float], delta: float = 0.1, sine: Sine = Sine(2.0, 10.0, 1.0),
                step: Step = Step(2.0, 0.4, 10.0), rate_hz: float = 1000.0) -> SensitivityTable:
    if not 0.0 < delta < 1.0:
        raise IdentificationError(f"delta = {delta} must be between 0 and 1 (a relative change)")
    base = np.array([params[name] for name in PARAMETER_NAMES], dtype=float)
    candidates = [base]
    for i in range(len(PARAMETER_NAMES)):
        for sign in (1.0, -1.0):
            changed = base.copy()
            changed[i] *= 1.0 + sign * delta
            candidates.append(changed)
    matrix = np.array(candidates)

    t = sample_times(sine.duration_s, rate_hz)
    sine_forces = simulate_driven(matrix, prepare_input(t, *sine.signals(t)))
    t_step = sample_times(step.duration_s, rate_hz)
    step_forces = simulate_driven(matrix, prepare_input(t_step, *step.signals(t_step)))
    rise_index = int(np.argmin(np.abs(t_step - step.rise_time_s)))

    values = {measure: {} for measure in MEASURES}
    rms = np.sqrt(np.mean(sine_forces[0] ** 2))
    for i, name in enumerate(PARAMETER_NAMES):
        plus, minus = 1 + 2 * i, 2 + 2 * i
        values["sine"][name] = float(np.sqrt(np.mean((sine_forces[plus] - sine_forces[minus]) ** 2))
                                     / (2 * delta * rms))
        for measure, index in (("step_rise", rise_index), ("step_end", -1)):
            values[measure][name] = float(abs(step_forces[plus, index] - step_forces[minus, index])
                                          / (2 * delta * abs(step_forces[0, index])))
    return SensitivityTable(values, delta)
