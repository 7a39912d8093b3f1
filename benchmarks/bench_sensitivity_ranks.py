"""Does our implementation rank the paper's 16 parameters as the paper's Tables 1 and 3 do?

    python benchmarks/bench_sensitivity_ranks.py

The sensitivity of each measure (the 10 Hz sine's rms force, the step's force at the end of its
rise and at 10 s) to a 10 % change of each parameter of Table 5 (identification.analysis.parameter_sensitivity),
ranked, against the ranks the paper computed in ADAMS (Tables 1 and 3, typed in
identification.analysis.parameter_sensitivity.PAPER_RANKS); prints Spearman's rho per measure and the parameter
ranked first. tests/identification/fitting/test_identification.py asserts rho > 0.7 and the first ranks.
"""
from __future__ import annotations

import time
from pathlib import Path

from scipy.stats import spearmanr

REPO = Path(__file__).resolve().parents[1]

from fmu_src.parameter_files import load_parameters  # noqa: E402
from fmu_src.models.proposed_model import PARAMETER_NAMES  # noqa: E402
from identification.analysis.parameter_sensitivity import MEASURES, PAPER_RANKS, sensitivity  # noqa: E402
import harness  # noqa: E402


def main() -> None:
    started = time.perf_counter()
    table = sensitivity(load_parameters(REPO / "data" / "params_table5_combined.json"))
    print(harness.provenance())
    print(f"{'measure':12s} {'Spearman rho':>12s}  first (ours)  first (paper)")
    for measure in MEASURES:
        ranks = table.ranks(measure)
        rho = spearmanr([ranks[n] for n in PARAMETER_NAMES], [PAPER_RANKS[measure][n] for n in PARAMETER_NAMES])
        ours = min(ranks, key=ranks.get)
        paper = min(PAPER_RANKS[measure], key=PAPER_RANKS[measure].get)
        print(f"{measure:12s} {rho.statistic:12.2f}  {ours:12s}  {paper}")
    print(f"{time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
