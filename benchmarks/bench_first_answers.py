"""A newcomer's first answers (issue 50): the first fit and the first ``compare`` of the paper's
protocol, with an empty compiled-model cache and with a filled one.

    python benchmarks/bench_first_answers.py [--fit] [--compare] [--workers N]

The paper's protocol is the synthetic Table 5 tests of ``data/``: the 2 mm / 10 Hz sine and the
2 mm step with a 0.4 s rise. Every run is a fresh ``python -m identification`` process, timed
whole (process start, imports, compiling or loading the models, the fit); each empty-cache run
gets a new, empty $BUSHING_CACHE_DIR, the filled-cache runs reuse the folder the empty run filled.

- ``--fit``: the default fit of the proposed model (its ensemble included), empty cache, then
  filled twice; prints each run's wall time, the fit's own clock and whether it is at the floor
  (issue 50's targets: <= 60 s with an empty cache, the filled one <= 0.5x today's).
- ``--compare``: ``compare`` over every model, empty cache, then filled; prints the wall times and
  the recommendation (target: <= 150 s with an empty cache, the same recommendation).
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
import harness

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "data"
PROTOCOL = ["--sine", str(DATA / "synthetic_table5_sine_2mm_10Hz.csv"),
            "--step", str(DATA / "synthetic_table5_step_2mm_rise0.4s.csv"), "--rise-time", "0.4"]


def timed(arguments: list[str], cache: Path) -> tuple[float, str]:
    """(wall time [s], stdout) of ``python -m identification <arguments>`` with ``cache`` as the
    compiled models' folder."""
    environment = dict(os.environ, BUSHING_CACHE_DIR=str(cache))
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "identification", *arguments], env=environment, cwd=REPO,
                          capture_output=True, text=True)
    wall = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(f"python -m identification {' '.join(arguments)} failed:\n{done.stderr[-3000:]}")
    return wall, done.stdout


def first_fit(workers: int) -> None:
    with tempfile.TemporaryDirectory() as folder:
        cache, out = Path(folder) / "cache", Path(folder) / "fit.json"
        for run in ("empty cache", "filled cache #1", "filled cache #2"):
            wall, printed = timed(["fit", *PROTOCOL, "--workers", str(workers), "--out", str(out)], cache)
            clock = re.search(r"simulations in ([0-9.]+) s", printed)
            misfit = re.search(r"misfit chi\^2/n = ([0-9.]+)", printed)
            print(f"first fit of the paper's protocol, {run:16s}: {wall:6.1f} s wall "
                  f"(the fit's clock {clock.group(1) if clock else '?'} s; misfit chi^2/n "
                  f"{misfit.group(1) if misfit else '?'})")


def first_compare(workers: int) -> None:
    with tempfile.TemporaryDirectory() as folder:
        cache = Path(folder) / "cache"
        for run in ("empty cache", "filled cache"):
            wall, printed = timed(["compare", *PROTOCOL, "--workers", str(workers), "--quiet",
                                   "--out", str(Path(folder) / "compare")], cache)
            recommended = printed.strip().splitlines()[-1] if printed.strip() else "?"
            print(f"compare over every model, {run:12s}: {wall:6.1f} s wall; {recommended}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fit", action="store_true", help="the first fit, empty cache then filled (minutes)")
    parser.add_argument("--compare", action="store_true", help="compare over every model, empty then filled "
                                                               "(ten minutes or more)")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    print(harness.provenance())
    if args.fit:
        first_fit(args.workers)
    if args.compare:
        first_compare(args.workers)


if __name__ == "__main__":
    main()
