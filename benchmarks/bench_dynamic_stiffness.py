"""How fast is the dynamic-stiffness characterisation? (issue target: a 5 x 7 grid of one
parameter set in under 2 s on the 2-core machine)

    python benchmarks/bench_dynamic_stiffness.py [--repeats 5]

Prints, for the default grid (amplitudes 0.1-3 mm x frequencies 1-50 Hz, 35 cases) of the
paper's Table 5 set: the first call in this process (loading numba's cached machine code, or
compiling it on a fresh machine), then the best and median of ``--repeats`` calls, the cycles
the cases needed, and the same for an ensemble of 20 members (Table 5 with k0 and c1 moved).
"""
from __future__ import annotations

import argparse
import statistics
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification.forward.dynamic_stiffness import characterise  # noqa: E402
import harness  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    table5 = load_parameters(REPO / "data" / "params_table5_combined.json")
    print(harness.provenance())
    _, (first,) = harness.timed(lambda: characterise(table5), 1)
    table, times = harness.timed(lambda: characterise(table5), args.repeats)
    print(f"one set, {len(table)} cases: first call {first:.2f} s (cache load or compile), then best "
          f"{min(times):.3f} s, median {statistics.median(times):.3f} s; cycles per case "
          f"{table.cycles.min()}-{table.cycles.max()} (median {int(np.median(table.cycles))})")
    rng = np.random.default_rng(0)
    members = [table5] + [dict(table5, k0=table5["k0"] * f, c1=table5["c1"] * g)
                          for f, g in rng.uniform(0.8, 1.2, (19, 2))]
    ensemble, times = harness.timed(lambda: characterise(members), args.repeats)
    print(f"ensemble of {len(members)} sets, {len(ensemble)} cases: best {min(times):.3f} s, "
          f"median {statistics.median(times):.3f} s")


if __name__ == "__main__":
    main()
