"""``compare``'s race on the project's comparison cases (issue 50): the time, the recommendation,
and how far each model's least-squares stages lowered its best screened misfit.

    python benchmarks/bench_race.py [CASE ...] [--workers N] [--only race|all|stages]

Every case runs ``python -m identification compare`` twice, side by side in one run, with the
compiled models' cache as it is (run once before to fill it):

- ``all``: every model runs its stages and every ensemble is sampled (``--no-race
  --every-ensemble``: compare before the race);
- ``race``: the default (a model that cannot win stops after its screening; the ensemble of the
  recommended model only);
- ``stages`` (only with ``--only stages``): every model runs its stages, no ensemble but the
  recommended model's (``--no-race``): the factors below without the ensembles' time.

Prints per case the two wall times and recommendations, and per model of the ``all`` (or
``stages``) run its best chi^2/n after the screening, after the first least-squares stage, before
the last stage and at the end, and the factors the later stages closed (first stage over final:
``identification.analysis.race.RACE_CLOSING`` must stay above the largest, with a margin; before
the last stage over final: ``RACE_CLOSING_LAST``), and which models the race stopped.

The cases (data/): ``table5`` the paper's synthetic Table 5 sine and step (held out: its random
input and the Table 6 grid); ``filled-rubber`` the synthetic filled rubber's two sines and step
(held out: random, 0.1 mm / 30 Hz, the data sheet); ``hydraulic`` and ``free-decoupler`` the
synthetic mounts' training sheet and 1 mm / 8 Hz sine (held out: the unseen sheet);
``friction-damper`` the real damper's 0.5 Hz, 1 in sine (held out: its other sines).
"""
from __future__ import annotations

import argparse
import csv
import subprocess
import sys
import tempfile
import time
from pathlib import Path
import harness

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "data"
FILLED = DATA / "synthetic_filled_rubber"
BRFD = DATA / "brfd"
DAMPER_TRAINING = BRFD / "sine_0.5Hz30lbtension1amplitude.csv.gz"

CASES = {
    "table5": ["--sine", f"{DATA}/synthetic_table5_sine_2mm_10Hz.csv", "--step",
               f"{DATA}/synthetic_table5_step_2mm_rise0.4s.csv", "--rise-time", "0.4",
               "--validate", f"{DATA}/synthetic_table5_random_2mm.csv",
               "--validate-kdyn", f"{DATA}/kdyn_table5_table6_grid.csv"],
    "filled-rubber": ["--sine", f"{FILLED}_sine_2mm_10Hz.csv", "--sine", f"{FILLED}_sine_0.5mm_3Hz.csv",
                      "--step", f"{FILLED}_step_2mm_rise0.4s.csv", "--rise-time", "0.4",
                      "--validate", f"{FILLED}_random_2mm.csv", "--validate", f"{FILLED}_sine_0.1mm_30Hz.csv",
                      "--validate-kdyn", f"{DATA}/kdyn_synthetic_filled_rubber.csv"],
    "hydraulic": ["--kdyn", f"{DATA}/kdyn_synthetic_hydraulic_train.csv",
                  "--sine", f"{DATA}/synthetic_hydraulic_sine_1mm_8Hz.csv",
                  "--validate-kdyn", f"{DATA}/kdyn_synthetic_hydraulic_unseen.csv"],
    "free-decoupler": ["--kdyn", f"{DATA}/kdyn_synthetic_free_decoupler_train.csv",
                       "--sine", f"{DATA}/synthetic_free_decoupler_sine_1mm_8Hz.csv",
                       "--validate-kdyn", f"{DATA}/kdyn_synthetic_free_decoupler_unseen.csv"],
    "friction-damper": ["--sine", str(DAMPER_TRAINING)]
                       + [a for path in sorted(BRFD.glob("sine_*.csv.gz")) if path != DAMPER_TRAINING
                          for a in ("--validate", str(path))],
}
RUNS = {"all": ["--no-race", "--every-ensemble"], "race": []}
EVERY_STAGE = {"stages": ["--no-race"]}


def compare(case: str, run: str, workers: int, out: Path) -> tuple[float, str, dict]:
    """(wall time [s], the recommendation, comparison.csv's rows by model) of one compare."""
    arguments = [sys.executable, "-m", "identification", "compare", *CASES[case], *{**RUNS, **EVERY_STAGE}[run],
                 "--workers",
                 str(workers), "--quiet", "--out", str(out)]
    started = time.perf_counter()
    done = subprocess.run(arguments, cwd=REPO, capture_output=True, text=True)
    wall = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(arguments)} failed:\n{done.stderr[-3000:]}")
    with open(out / "comparison.csv") as handle:
        rows = {row["model"]: row for row in csv.DictReader(handle)}
    return wall, done.stdout.strip().splitlines()[-1], rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", nargs="*", metavar="CASE", help=f"of {', '.join(CASES)} (default: all)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--only", choices=list(RUNS) + list(EVERY_STAGE), help="one of the runs per case")
    args = parser.parse_args()
    unknown = [case for case in args.cases if case not in CASES]
    if unknown:
        parser.error(f"unknown cases {', '.join(unknown)}: choose from {', '.join(CASES)}")
    print(harness.provenance(), flush=True)
    closing, closing_last = [], []
    for case in args.cases or list(CASES):
        with tempfile.TemporaryDirectory() as folder:
            outcome = {run: compare(case, run, args.workers, Path(folder) / run)
                       for run in ([args.only] if args.only else RUNS)}
        for run, (wall, recommended, rows) in outcome.items():
            stopped = [model for model, row in rows.items() if row["stopped_after_screening"]]
            print(f"{case:15s} {run:4s}: {wall:6.1f} s wall; {recommended}"
                  + (f"; stopped after screening: {', '.join(stopped)}" if stopped else ""), flush=True)
        for run in ("all", "stages"):
            for model, row in outcome.get(run, (0, "", {}))[2].items():
                if row["first_stage_misfit_chi2_per_residual"]:
                    screened, first, before_last, final = (float(row[column]) for column in (
                        "screened_misfit_chi2_per_residual", "first_stage_misfit_chi2_per_residual",
                        "before_last_stage_misfit_chi2_per_residual", "misfit_chi2_per_residual"))
                    closing.append((first / final, case, model))
                    closing_last.append((before_last / final, case, model))
                    print(f"    {model:26s} chi2/n screened {screened:10.4g}  first stage {first:10.4g}  before the "
                          f"last {before_last:10.4g}  final {final:10.4g}  later stages closed {first / final:7.3g}x, "
                          f"the last {before_last / final:7.3g}x", flush=True)
        if len(outcome) == 2:
            same = outcome["all"][1] == outcome["race"][1]
            print(f"    race / all: {outcome['race'][0] / outcome['all'][0]:.2f} of the time; "
                  f"{'the same recommendation' if same else 'A DIFFERENT RECOMMENDATION'}", flush=True)
    if closing:
        factor, case, model = max(closing)
        print(f"the largest factor the stages after the first closed: {factor:.3g}x ({model}, {case})")
        factor, case, model = max(closing_last)
        print(f"the largest factor the last stage closed: {factor:.3g}x ({model}, {case})")


if __name__ == "__main__":
    main()
