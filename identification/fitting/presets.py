"""The search presets, defined once: how much of each search phase a fit runs.

``fit(preset=...)``, the command line's ``--preset`` (its choices and help) and the parameter
file's provenance all read them here. ``FitOptions``: a fit's settings (a preset among them) as
one value. The front doors (``fit``, ``fit_many``) take them as keywords, as they always have,
turn them into one ``FitOptions`` (``FitOptions.of``) and pass that on; the layers below take the
value, not the keywords again. A keyword they do not know is refused by name.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any, Mapping

PAPER_GA = {"population": 300, "generations": 200, "crossover_probability": 0.8, "mutation_probability": 0.05}
"""The paper's genetic algorithm (pymoo: uniform crossover, polynomial mutation per coordinate)."""


SOBOL = "sobol"
GENETIC = "genetic"
GLOBAL_SEARCHES = (SOBOL, GENETIC)
"""A fit's global phase: scrambled Sobol points screened (``multistart.screen``), or the paper's GA
(``multistart.genetic_algorithm``, ``PAPER_GA``), whose final population ranks the starts."""


@dataclass(frozen=True)
class SearchSettings:
    """How much search a fit runs, and how: ``screening`` global points (Sobol points, or the GA's
    population) found by ``global_search`` (``GLOBAL_SEARCHES``), then ``stages`` of (starts,
    largest number of least-squares evaluations of each)."""
    screening: int
    stages: tuple[tuple[int, int], ...]
    global_search: str = SOBOL
    prefix_fraction: float | None = None
    """Where the training is time series alone: every Sobol point is screened first on this
    fraction of each test (its start), and only the best ``prefix_kept`` of them on the whole
    tests (``multistart.screen``). None: every point on the whole tests."""
    prefix_kept: float = 1.0 / 8.0

    @property
    def genetic(self) -> bool:
        """Whether the global phase is the paper's GA (no starts read off the data then)."""
        return self.global_search == GENETIC

    def global_evaluations(self, screened: int) -> int:
        """The simulations the global phase ran, ``screened`` points kept."""
        return PAPER_GA["population"] * PAPER_GA["generations"] if self.genetic else screened

    def __post_init__(self):
        if self.global_search not in GLOBAL_SEARCHES:
            raise ValueError(f"global search {self.global_search!r}: choose one of {', '.join(GLOBAL_SEARCHES)}")
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
        if self.prefix_fraction is not None and not (0.0 < self.prefix_fraction < 1.0 and 0.0 < self.prefix_kept <= 1.0):
            raise ValueError(f"screening prefix {self.prefix_fraction} of each test, best {self.prefix_kept} kept: "
                             "both must be fractions in (0, 1)")


_STAGES = ((128, 10), (24, 30), (6, 300))
SCREENING_PREFIX = 0.1
"""The default preset screens its 8192 Sobol points on the first tenth of each test, then the best
eighth of them on the whole tests: on the paper's Table 5 sine and step the 128 points that start the
least squares are the same ones (the worst of them 253rd on the tenth), and the global phase takes
5.4 s instead of 8.2 s on the project's 2-core VM."""
PRESETS = {
    "default": SearchSettings(screening=8192, stages=_STAGES, prefix_fraction=SCREENING_PREFIX),
    # the paper's GA as the global stage (its final population ranks the starts)
    "paper": SearchSettings(screening=PAPER_GA["population"], stages=_STAGES, global_search=GENETIC),
}


FROM_A_FIT_SCREENING = 1.0 / 8.0
FROM_A_FIT_STARTS = 1.0 / 4.0
FROM_A_FIT_FINAL_STARTS = 3
"""A search that starts from a nested model's fit (``loop_start.FitStart``: ``compare``'s variants
of its recommended model) screens this share of the preset's points and runs this share of each
stage's starts, at least ``FROM_A_FIT_FINAL_STARTS`` to the end (two agreeing make a fit
converged): its best start is known to be the fit it nests (docs/benchmarks.md, "A test
matrix", measures what this costs and saves)."""


def from_a_fit(settings: SearchSettings) -> SearchSettings:
    """``settings`` for a search that starts from a nested model's fit (``FROM_A_FIT_*``); the
    paper's GA as it is."""
    if settings.genetic:
        return settings
    stages = tuple((min(starts, max(FROM_A_FIT_FINAL_STARTS, round(starts * FROM_A_FIT_STARTS))), evaluations)
                   for starts, evaluations in settings.stages)
    return replace(settings, screening=max(1, round(settings.screening * FROM_A_FIT_SCREENING)), stages=stages)


def global_phase(preset: str | SearchSettings) -> str:
    """What the preset's global phase is (or that of the settings given), in words."""
    settings = PRESETS[preset] if isinstance(preset, str) else preset
    if settings.genetic:
        return (f"the paper's GA (pymoo, population {PAPER_GA['population']}, "
                f"{PAPER_GA['generations']} generations)")
    if settings.prefix_fraction is not None:
        # no per cent sign: the command line's help is a %-format
        return (f"{settings.screening} scrambled Sobol points (with time series alone: screened on the first "
                f"{settings.prefix_fraction:g} of each test, the best {settings.prefix_kept:g} of them on the whole)")
    return f"{settings.screening} scrambled Sobol points"


def describe(preset: str | SearchSettings) -> str:
    """The preset's search (or the search the settings given run) in one sentence (the parameter
    file's ``method``)."""
    settings = PRESETS[preset] if isinstance(preset, str) else preset
    stages = ", ".join(f"{s} x {e}" for s, e in settings.stages)
    return (f"{global_phase(settings)}, then successive halving of bounded trust-region least squares "
            f"(starts x evaluations: {stages}) on chi^2/n over every sample")


@dataclass(frozen=True)
class FitOptions:
    """A fit's settings (``fit``'s keywords; see its docstring for each).

    What is searched and how: ``preset`` (``presets``), ``seed`` (>= 0), ``screening`` and
    ``starts`` (overrides of the preset's Sobol points and first-stage starts), ``ensemble``
    (profiles and posterior), ``jacobian`` (``exact`` or ``difference``), ``fixed`` (parameters
    held, model units). Further data fitted with the tests: ``kdyn`` (a dynamic-stiffness table
    or its path), ``multiaxis`` (multi-axis tests or paths) with their ``coupling``. Where it
    runs: ``workers`` (local processes, default every core), ``scheduler`` (a Dask cluster),
    ``engine`` (one to reuse), ``progress`` (bars on stderr)."""
    preset: str = "default"
    seed: int = 0
    screening: int | None = None
    starts: int | None = None
    ensemble: bool = True
    jacobian: str = "exact"
    fixed: Mapping[str, float] | None = None
    kdyn: Any = None
    multiaxis: Any = ()
    coupling: str | None = None
    workers: int | None = None
    scheduler: Any = None
    engine: Any = None
    progress: bool = True

    @classmethod
    def of(cls, options: FitOptions | None = None, /, **keywords) -> FitOptions:
        """``options`` (default: every default) with ``keywords`` put in; an unknown keyword
        raises TypeError naming it and the known ones."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(keywords) - known)
        if unknown:
            raise TypeError(f"unknown keyword{'s' if len(unknown) > 1 else ''} {', '.join(unknown)}; "
                            f"the fit takes {', '.join(f.name for f in fields(cls))}")
        return replace(options if options is not None else cls(), **keywords)
