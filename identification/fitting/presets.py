"""The search presets, defined once: how much of each search phase a fit runs.

``fit(preset=...)``, the command line's ``--preset`` (its choices and help) and the parameter
file's provenance all read them here.
"""
from __future__ import annotations

from dataclasses import dataclass

PAPER_GA = {"population": 300, "generations": 200, "crossover_probability": 0.8, "mutation_probability": 0.05}
"""The paper's genetic algorithm (pymoo: uniform crossover, polynomial mutation per coordinate)."""


@dataclass(frozen=True)
class SearchSettings:
    """How much search a fit runs: ``screening`` global points (Sobol, or the GA's population),
    then ``stages`` of (starts, largest number of least-squares evaluations of each)."""
    screening: int
    stages: tuple[tuple[int, int], ...]

    def __post_init__(self):
        if self.screening < 1:
            raise ValueError(f"screening = {self.screening} points: give 1 or more")
        if not self.stages:
            raise ValueError("at least one least-squares stage is needed")
        for starts, evaluations in self.stages:
            if starts < 1 or evaluations < 1:
                raise ValueError(f"stage ({starts} starts, {evaluations} evaluations): both must be >= 1")
        counts = [starts for starts, _ in self.stages]
        if counts != sorted(counts, reverse=True):
            raise ValueError(f"stage start counts {counts} must not grow")


_STAGES = ((128, 10), (24, 30), (6, 300))
PRESETS = {
    "default": SearchSettings(screening=8192, stages=_STAGES),
    # the paper's GA as the global stage (its final population ranks the starts)
    "paper": SearchSettings(screening=PAPER_GA["population"], stages=_STAGES),
}


def global_phase(preset: str) -> str:
    """What the preset's global phase is, in words."""
    if preset == "paper":
        return (f"the paper's GA (pymoo, population {PAPER_GA['population']}, "
                f"{PAPER_GA['generations']} generations)")
    return f"{PRESETS[preset].screening} scrambled Sobol points"


def describe(preset: str) -> str:
    """The preset's search in one sentence (the parameter file's ``method``)."""
    stages = ", ".join(f"{s} x {e}" for s, e in PRESETS[preset].stages)
    return (f"{global_phase(preset)}, then successive halving of bounded trust-region least squares "
            f"(starts x evaluations: {stages}) on chi^2/n over every sample")
